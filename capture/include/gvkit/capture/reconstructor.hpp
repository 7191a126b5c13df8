#pragma once
// Triangulation of decoded fringes: each camera pixel's ray intersected with the projector's
// column plane (a surface, when the projector lens is distorted). The Reconstructor keeps the
// per-pixel rays and plane coefficients of one calibration, so a stream of frames pays only a
// few operations per pixel (the speed-critical kernel of capture).

#include <memory>

#include <opencv2/core.hpp>

#include "gvkit/capture/lens_distortion.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct ReconstructOptions {
  // Pattern sets unwrapped spatially know each region's phase only up to whole periods: the
  // period offset is chosen so the region's median depth is nearest this (mm).
  double depth_prior_mm = 650;
  double min_depth_mm = 50, max_depth_mm = 20000;  // points outside are invalid
  bool reference = false;  // plain per-pixel OpenCV triangulation instead of the lookup tables

  Status check() const;
};

class Reconstructor {
 public:
  // Precomputes the per-pixel tables for the calibration's camera size. Fails when the
  // calibration does not check, uses an unsupported lens model, or cannot triangulate (the
  // baseline lies in the projector's column planes, so rays and planes are parallel).
  static Result<Reconstructor> create(const Calibration& calibration,
                                      const ReconstructOptions& options = {});

  // Decodes and triangulates one frame. The images must have the calibration's camera size.
  // A frame without any valid pixel (dark, no pattern) gives an empty scan and a logged warning.
  Result<RangeScan> reconstruct(const FringeSet& fringes, const PatternSet& patterns) const;

  // Triangulates a decoded frame (resolving relative regions by the depth prior).
  RangeScan triangulate(const PhaseMap& phase) const;

  // Camera-frame points (CV_32FC3, NaN where u is NaN or no intersection in the depth range)
  // for a map of projector columns u (CV_32F, camera size).
  cv::Mat triangulate_columns(const cv::Mat& projector_u) const;
  // The plain reference of triangulate_columns (cv::undistortPoints / cv::projectPoints per
  // pixel, double precision); slow.
  cv::Mat triangulate_columns_reference(const cv::Mat& projector_u) const;

  const Calibration& calibration() const { return calibration_; }
  cv::Size camera_size() const { return {calibration_.camera_width, calibration_.camera_height}; }

 private:
  Reconstructor() = default;
  // Depth (z, mm) of pixel i for projector column u, NaN when not in range.
  float depth_at(int i, float u) const;
  void resolve_regions(PhaseMap& phase) const;

  Calibration calibration_;
  ReconstructOptions options_;
  LensDistortion projector_lens_;
  cv::Mat ray_;          // CV_32FC3: (x, y, 1) undistorted normalized camera ray per pixel
  cv::Mat alpha_;        // CV_32F: see reconstructor.cpp
  cv::Mat beta_;         // CV_32F
  cv::Mat rotated_ray_;  // CV_64FC3: R_proj_from_cam * ray (only with projector distortion)
  double numerator_a_ = 0, numerator_b_ = 0;
};

// One-shot convenience: builds a Reconstructor and reconstructs one frame.
Result<RangeScan> reconstruct(const FringeSet& fringes, const PatternSet& patterns,
                              const Calibration& calibration,
                              const ReconstructOptions& options = {});

}  // namespace gvkit::capture
