#include "gvkit/player/geometry_error.hpp"

#include <cmath>
#include <limits>

namespace gvkit::player {
namespace {

Status check_same_size(cv::Size a, cv::Size b) {
  if (a == b) return Status::ok();
  return invalid_argument("reference is " + std::to_string(b.width) + "x" +
                          std::to_string(b.height) + " but the frame is " +
                          std::to_string(a.width) + "x" + std::to_string(a.height));
}

}  // namespace

Result<std::vector<float>> vertex_errors_mm(const MeshBuffers& mesh,
                                            const GeometryImage& reference) {
  GVKIT_RETURN_IF_ERROR(check_same_size(cv::Size(mesh.width, mesh.height), reference.size()));
  std::vector<float> errors(mesh.vertex_count(), std::numeric_limits<float>::quiet_NaN());
  const auto* ref = reference.xyz_mm.ptr<cv::Vec3f>();
  const uint8_t* mask = reference.domain_mask.ptr<uint8_t>();
  for (size_t i = 0; i < mesh.vertex_count(); ++i) {
    const int p = mesh.pixel_index[i];
    if (!mask[p]) continue;
    const cv::Vec3f d = cv::Vec3f(mesh.positions_mm[3 * i], mesh.positions_mm[3 * i + 1],
                                  mesh.positions_mm[3 * i + 2]) -
                        ref[p];
    errors[i] = std::sqrt(d.dot(d));
  }
  return errors;
}

Result<GeometryErrorStats> geometry_error(const GeometryImage& image,
                                          const GeometryImage& reference, double peak_mm) {
  GVKIT_RETURN_IF_ERROR(check_same_size(image.size(), reference.size()));
  GeometryErrorStats s;
  double sum2 = 0;
  cv::Vec3d lo(INFINITY, INFINITY, INFINITY), hi = -lo;
  for (int y = 0; y < image.xyz_mm.rows; ++y) {
    const auto* a = image.xyz_mm.ptr<cv::Vec3f>(y);
    const auto* b = reference.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* ma = image.domain_mask.ptr<uint8_t>(y);
    const uint8_t* mb = reference.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < image.xyz_mm.cols; ++x) {
      if (!mb[x]) continue;
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], static_cast<double>(b[x][k]));
        hi[k] = std::max(hi[k], static_cast<double>(b[x][k]));
      }
      if (!ma[x]) continue;
      const cv::Vec3d d = cv::Vec3d(a[x]) - cv::Vec3d(b[x]);
      const double e2 = d.dot(d);
      sum2 += e2;
      s.max_mm = std::max(s.max_mm, std::sqrt(e2));
      ++s.pixels;
    }
  }
  if (s.pixels == 0) return failed_precondition("frame and reference share no domain pixel");
  s.rms_mm = std::sqrt(sum2 / static_cast<double>(s.pixels));
  s.peak_mm = peak_mm > 0 ? peak_mm : cv::norm(hi - lo);
  s.psnr_db = s.rms_mm > 0 ? 20.0 * std::log10(s.peak_mm / s.rms_mm)
                           : std::numeric_limits<double>::infinity();
  return s;
}

}  // namespace gvkit::player
