// Reconstructs the real SLStudio skull (../shared/data/slstudio-skull-2x3, 2x3 scheme) and writes
// a shaded picture of the surface (normals from the scan's xyz, Lambertian light from the
// camera's upper left), for docs/.
//   capture_skull_render OUTPUT.png
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/core/calibration_io.hpp"

int main(int argc, char** argv) {
  using namespace gvkit;
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT.png\n", argv[0]);
    return 2;
  }
  const char* env = std::getenv("GVKIT_SHARED_DATA");
  const std::filesystem::path dir =
      std::filesystem::path(env ? env : GVKIT_SHARED_DATA_DIR) / "slstudio-skull-2x3";
  auto calibration = read_calibration(dir / "calibration.xml");
  auto patterns = capture::create_pattern_set("mf3-f16-f1");
  if (!calibration || !patterns) {
    std::fprintf(stderr, "cannot read the skull data\n");
    return 1;
  }
  auto folder = capture::list_fringe_folder(dir, (*patterns)->image_count());
  auto fringes =
      folder ? capture::read_fringe_frame(*folder, 0) : Result<FringeSet>(folder.status());
  if (!fringes) {
    std::fprintf(stderr, "%s\n", fringes.status().message().c_str());
    return 1;
  }
  auto scan = capture::reconstruct(*fringes, **patterns, calibration->calibration);
  if (!scan) {
    std::fprintf(stderr, "%s\n", scan.status().message().c_str());
    return 1;
  }
  const cv::Mat& xyz = scan->xyz_mm;
  cv::Mat out(xyz.size(), CV_8UC3, cv::Scalar(40, 30, 25));
  const cv::Vec3f light = cv::normalize(cv::Vec3f(-0.4f, -0.5f, -1.0f));
  for (int y = 1; y + 1 < xyz.rows; ++y)
    for (int x = 1; x + 1 < xyz.cols; ++x) {
      const cv::Vec3f l = xyz.at<cv::Vec3f>(y, x - 1), r = xyz.at<cv::Vec3f>(y, x + 1),
                      u = xyz.at<cv::Vec3f>(y - 1, x), d = xyz.at<cv::Vec3f>(y + 1, x);
      if (std::isnan(l[2] + r[2] + u[2] + d[2])) continue;
      cv::Vec3f n = (r - l).cross(d - u);
      const float len = static_cast<float>(cv::norm(n));
      if (len == 0) continue;
      n /= len;
      if (n[2] > 0) n = -n;  // facing the camera
      const float shade = 0.15f + 0.85f * std::max(0.0f, n.dot(light));
      const uint8_t v = static_cast<uint8_t>(std::min(255.0f, 255.0f * shade));
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(v * 0.92f), v, v);
    }
  cv::resize(out, out, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  if (!cv::imwrite(argv[1], out)) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::printf("wrote %s (%d valid points)\n", argv[1], cv::countNonZero(scan->valid));
  return 0;
}
