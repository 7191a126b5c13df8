#include "gvkit/capture/ground_truth.hpp"

#include <cmath>

#include "gvkit/core/exr_io.hpp"

namespace gvkit::capture {

GroundTruth ground_truth_of(const SyntheticTruth& truth, const SyntheticScene& scene) {
  GroundTruth gt;
  gt.xyz_mm = truth.xyz_mm.clone();
  gt.barycentric = truth.barycentric.clone();
  gt.lit = truth.lit.clone();
  gt.polygon = cv::Mat(truth.triangle.size(), CV_32S, cv::Scalar(-1));
  gt.vertices = cv::Mat(truth.triangle.size(), CV_32SC3, cv::Scalar::all(-1));
  for (int y = 0; y < gt.polygon.rows; ++y)
    for (int x = 0; x < gt.polygon.cols; ++x) {
      const int t = truth.triangle.at<int>(y, x);
      if (t < 0) continue;
      gt.polygon.at<int>(y, x) = scene.triangle_source.empty() ? t : scene.triangle_source[t];
      gt.vertices.at<cv::Vec3i>(y, x) = scene.triangles[t];
    }
  return gt;
}

Status write_ground_truth_exr(const std::filesystem::path& path, const GroundTruth& truth) {
  ExrChannels channels;
  std::vector<cv::Mat> xyz, bary, vertices;
  cv::split(truth.xyz_mm, xyz);
  cv::split(truth.barycentric, bary);
  cv::split(truth.vertices, vertices);
  channels["X"] = xyz[0];
  channels["Y"] = xyz[1];
  channels["Z"] = xyz[2];
  truth.polygon.convertTo(channels["F"], CV_32F);
  for (int k = 0; k < 3; ++k) {
    vertices[k].convertTo(channels["V" + std::to_string(k)], CV_32F);
    channels["B" + std::to_string(k)] = bary[k];
  }
  truth.lit.convertTo(channels["L"], CV_32F, 1.0 / 255.0);
  return write_exr(path, channels);
}

Result<GroundTruth> read_ground_truth_exr(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(ExrChannels channels, read_exr(path));
  for (const char* name : {"X", "Y", "Z", "F", "V0", "V1", "V2", "B0", "B1", "B2", "L"})
    if (!channels.count(name))
      return corrupt_data(path.string() + ": ground truth channel " + name + " is missing");
  GroundTruth gt;
  cv::merge(std::vector<cv::Mat>{channels["X"], channels["Y"], channels["Z"]}, gt.xyz_mm);
  cv::merge(std::vector<cv::Mat>{channels["B0"], channels["B1"], channels["B2"]}, gt.barycentric);
  channels["F"].convertTo(gt.polygon, CV_32S);
  std::vector<cv::Mat> v(3);
  for (int k = 0; k < 3; ++k) channels["V" + std::to_string(k)].convertTo(v[k], CV_32S);
  cv::merge(v, gt.vertices);
  channels["L"].convertTo(gt.lit, CV_8U, 255.0);
  return gt;
}

}  // namespace gvkit::capture
