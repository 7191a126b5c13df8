#include "gvkit/capture/scan_accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace gvkit::capture {

ScanAccuracy scan_accuracy(const RangeScan& scan, const GroundTruth& truth, int face_vertex_count) {
  GVKIT_CHECK(scan.size() == truth.xyz_mm.size(), "scan and truth sizes differ");
  const cv::Size size = scan.size();
  cv::Mat face(size, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const cv::Vec3i v = truth.vertices.at<cv::Vec3i>(y, x);
      face.at<uint8_t>(y, x) =
          (truth.lit.at<uint8_t>(y, x) && v[0] >= 0 && v[0] < face_vertex_count &&
           v[1] < face_vertex_count && v[2] < face_vertex_count)
              ? 255
              : 0;
    }
  cv::Mat interior;
  cv::erode(face, interior, cv::Mat::ones(3, 3, CV_8U), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
            cv::Scalar(0));
  ScanAccuracy a;
  std::vector<double> errors;
  double sum2 = 0, interior_sum2 = 0;
  int64_t interior_valid = 0;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const bool in = interior.at<uint8_t>(y, x) != 0;
      a.face_interior_px += in;
      const float zt = truth.xyz_mm.at<cv::Vec3f>(y, x)[2];
      if (!scan.valid.at<uint8_t>(y, x) || !std::isfinite(zt)) continue;
      const double e = std::abs(scan.xyz_mm.at<cv::Vec3f>(y, x)[2] - zt);
      errors.push_back(e);
      sum2 += e * e;
      a.max_mm = std::max(a.max_mm, e);
      if (in) {
        ++interior_valid;
        interior_sum2 += e * e;
        a.face_interior_max_mm = std::max(a.face_interior_max_mm, e);
      }
    }
  a.compared_px = static_cast<int64_t>(errors.size());
  if (!errors.empty()) {
    a.rms_mm = std::sqrt(sum2 / errors.size());
    const size_t k = std::min(errors.size() - 1, static_cast<size_t>(0.99 * errors.size()));
    std::nth_element(errors.begin(), errors.begin() + k, errors.end());
    a.p99_mm = errors[k];
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.begin() + k);
    a.p50_mm = errors[errors.size() / 2];
  }
  if (interior_valid > 0) a.face_interior_rms_mm = std::sqrt(interior_sum2 / interior_valid);
  if (a.face_interior_px > 0)
    a.face_interior_valid_share = static_cast<double>(interior_valid) / a.face_interior_px;
  return a;
}

}  // namespace gvkit::capture
