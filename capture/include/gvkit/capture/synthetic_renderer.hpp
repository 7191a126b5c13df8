#pragma once
// Synthetic projector-camera: renders the camera images of a triangle mesh lit by projected
// patterns, with exact ground truth. Effects: projector shadows, camera occlusion (z-buffer),
// per-vertex albedo, ambient light, Lambertian shading, projector gamma and bit depth, defocus
// blur of projector and camera, camera noise, 8/10/12/16-bit quantization. Lens distortion of
// both devices is honoured (rasterization on undistorted per-pixel rays).

#include <cstdint>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

// A triangle mesh in the camera frame (mm).
struct SyntheticScene {
  std::vector<cv::Vec3d> positions_mm;  // camera frame
  std::vector<cv::Vec3i> triangles;     // indices into positions_mm
  std::vector<int> triangle_source;     // per triangle: an id reported in the ground truth
                                        // (e.g. the model's polygon index); may be empty
  std::vector<float> albedo;            // per vertex, in [0, 1]
};

struct RenderOptions {
  double ambient = 0.08;          // light reaching every surface point, relative to the projector
  double projector_power = 0.85;  // irradiance of a full-white projector pixel, facing it
  double projector_gamma = 1.0;   // the projector emits value^gamma (patterns are sent as is)
  int projector_bit_depth = 8;    // patterns are quantized to this before gamma (0 = no)
  double projector_blur_px = 0;   // Gaussian defocus sigma on the projector image (px)
  double camera_blur_px = 0;      // Gaussian defocus sigma on the camera image (px)
  double noise_sigma = 0;         // camera noise, standard deviation as a fraction of the range
  int bit_depth = 8;              // camera: 8 (CV_8U), 10, 12 or 16 (CV_16U, scaled to 65535)
  double shadow_bias_mm = 1.0;    // depth tolerance of the projector shadow test

  Status check() const;
  nlohmann::json to_json() const;  // the image-forming options, as recorded in session.json
};

// Ground truth of one camera image: what each pixel sees.
struct SyntheticTruth {
  cv::Mat xyz_mm;       // CV_32FC3, camera frame, NaN where no surface
  cv::Mat triangle;     // CV_32S, index into scene.triangles, -1 where no surface
  cv::Mat barycentric;  // CV_32FC3, weights of the triangle's 3 vertices (sum 1)
  cv::Mat lit;          // CV_8U, 255 where the surface is seen and lit by the projector
};

struct SyntheticFrame {
  std::vector<cv::Mat> images;  // one per pattern, CV_8U or CV_16U (bit_depth)
  SyntheticTruth truth;
};

class SyntheticRenderer {
 public:
  // Precomputes per-pixel rays of both devices. Contract: calibration.check() is ok and options
  // check.
  SyntheticRenderer(const Calibration& calibration, const RenderOptions& options);

  // Renders one instant: the camera image under each projector pattern (CV_32F in [0, 1], the
  // projector's size). `seed` makes the noise deterministic. Thread-safe (const).
  SyntheticFrame render(const SyntheticScene& scene, const std::vector<cv::Mat>& patterns,
                        uint64_t seed) const;

  const Calibration& calibration() const { return calibration_; }
  const RenderOptions& options() const { return options_; }

 private:
  Calibration calibration_;
  RenderOptions options_;
  cv::Mat camera_rays_;     // CV_32FC2 undistorted normalized coordinates per camera pixel
  cv::Mat projector_rays_;  // CV_32FC2 per projector pixel
};

}  // namespace gvkit::capture
