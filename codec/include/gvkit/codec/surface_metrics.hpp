#pragma once
// Shading-sensitive quality figures of a decoded geometry image against its input, beside the
// point-error figures of geometry_metrics.hpp: a decoded surface can have a small point error
// and still look crumpled (ripples tilt the normals, which shading shows) or notched at its
// outline. Two figures, over the valid pixels (inside the reference's domain mask, xyz finite
// in both images):
//   - normal-angle error: the angle (degrees) between the two images' unit normals at each
//     pixel, both from the same fixed grid stencil (grid_normals) after the same light smoothing
//     (SurfaceErrorOptions::normal_scale_px), pooled as mean, percentiles and max;
//   - Hausdorff distance (mm): the largest distance from a vertex (valid pixel) of one surface
//     to the other surface (its grid triangles), both directions; also over the outline pixels
//     alone (valid pixels with a 4-neighbour outside the valid set).

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

struct SurfaceErrorOptions {
  // The nearest point of the other surface is searched on its triangles within +-window_px
  // pixels of the same pixel (1..16). A vertex farther than that from the other surface (a
  // tangential shift of more than window_px pixels) gets the distance to the nearest triangle
  // in the window: an upper bound of its true distance.
  int window_px = 3;
  // Normals are compared at this scale: both surfaces' positions are smoothed by the same
  // Gaussian of this standard deviation (pixels; over valid pixels only, normalised) before
  // their grid normals are taken; 0 compares the raw per-pixel normals. The raw normals of a
  // reconstructed face carry its measurement noise (on the main-job video, coding it with a
  // 0.05 mm bound already turns them by 4.3 degrees at the 95th percentile), detail the player's
  // default view does not resolve: a 320x320 face fills about 250 screen pixels of its 640x480
  // picture, and its 4x multisampling blurs over about 1.5 screen pixels, i.e. 2 geometry
  // pixels. Ripples of 8 pixels and longer pass a 2-pixel Gaussian at 30 % and more (16 px: 73
  // %), so what a viewer sees as crumpling stays in the figure (docs/benchmarks.md, "Surface
  // metrics"). 0..8.
  double normal_scale_px = 2.0;
  Status check() const;
};

// The pixels both images have a surface at: reference.domain_mask != 0 and xyz finite in both
// (CV_8U, 255 = valid). Sizes must match (contract).
cv::Mat surface_valid_pixels(const GeometryImage& reference, const GeometryImage& decoded);

// Unit normal (CV_32FC3) of each valid pixel p of xyz_mm (CV_32FC3) from a fixed stencil: the
// sum of the cross products (r - p) x (d - p), (d - p) x (l - p), (l - p) x (u - p),
// (u - p) x (r - p) over the quadrants whose two 4-neighbours (right, down, left, up) are valid
// too, normalised (area-weighted, independent of where the image's triangulation splits its
// quads). NaN where p is not valid, has no such quadrant, or the sum is zero. valid: CV_8U.
cv::Mat grid_normals(const cv::Mat& xyz_mm, const cv::Mat& valid);

// xyz_mm (CV_32FC3) smoothed by a Gaussian of standard deviation sigma_px over the valid pixels
// (CV_8U): each valid pixel becomes the Gaussian-weighted mean of the valid pixels around it
// (separable, truncated at 3 sigma); invalid pixels are copied. sigma_px <= 0 returns a copy.
cv::Mat smooth_positions(const cv::Mat& xyz_mm, const cv::Mat& valid, double sigma_px);

// Per pixel: the angle (degrees, 0..180) between the reference's and the decoded image's grid
// normals at the options' scale over surface_valid_pixels (CV_32F; NaN where either normal is
// undefined).
cv::Mat normal_error_deg(const GeometryImage& reference, const GeometryImage& decoded,
                         const SurfaceErrorOptions& options = {});

// Per pixel: the distance (mm) from the decoded image's vertex to the reference surface (its grid
// triangles within the options' window) over surface_valid_pixels (CV_32F; NaN elsewhere): where
// the decoded surface lies off the input, e.g. a notch in its outline.
cv::Mat surface_distance_mm(const GeometryImage& reference, const GeometryImage& decoded,
                            const SurfaceErrorOptions& options = {});

// Figures of one frame, or pooled over several (accumulate).
struct SurfaceError {
  static constexpr double kBinDeg = 0.01;  // angle histogram resolution
  static constexpr int kBins = 18001;      // 0 .. 180 degrees
  std::vector<int64_t> angle_histogram;    // kBins counts (empty while no pixel is counted)
  double angle_sum_deg = 0;
  double normal_max_deg = 0;
  int64_t normal_pixels = 0;  // pixels with both normals defined
  double hausdorff_mm = 0;    // max of both directed vertex-to-surface distances
  // Directed maxima: reference vertices to the decoded surface, and the reverse.
  double to_decoded_max_mm = 0, to_reference_max_mm = 0;
  double outline_hausdorff_mm = 0;  // over outline vertices of either surface
  double distance_sum_mm = 0;       // over both directions' vertices
  int64_t distance_samples = 0;

  double normal_mean_deg() const;
  // The q-quantile (0..1) of the per-pixel angle errors, interpolated inside its histogram bin
  // (+-0.01 degree); 0 without pixels.
  double normal_percentile_deg(double q) const;
  double normal_p95_deg() const { return normal_percentile_deg(0.95); }
  // Mean vertex-to-surface distance over both directions (mm).
  double surface_mean_mm() const;
};

// The figures of decoded against reference (same size: contract; the reference's domain mask
// decides). Throws ContractError when options fail check().
SurfaceError surface_error(const GeometryImage& reference, const GeometryImage& decoded,
                           const SurfaceErrorOptions& options = {});

// Pools frames: histogram, sums and counts added, maxima kept.
void accumulate(SurfaceError& total, const SurfaceError& frame);

}  // namespace gvkit::codec
