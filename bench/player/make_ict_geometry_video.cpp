// make_ict_geometry_video ICT_DIR OUT_DIR [SIZE] [FRAMES]: writes an expression sequence of the
// ICT-FaceKit face (jaw opening, smiling, blinking) as SIZE x SIZE geometry-image EXRs, by
// rasterizing the face area (vertices 0..9408) in the model's UV layout. Positions in mm, model
// frame (y up, z towards the viewer); eyes and mouth are holes of the domain. Material for the
// player benchmark and the README picture until the facemap/codec pipeline produces real ones.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/json_io.hpp"

namespace {
using namespace gvkit;

GeometryImage rasterize(const IctFaceModel& model, const std::vector<cv::Vec3d>& xyz_mm, int size,
                        cv::Vec2f uv_lo, cv::Vec2f uv_hi) {
  GeometryImage image;
  image.xyz_mm = cv::Mat(size, size, CV_32FC3, cv::Scalar::all(0));
  image.domain_mask = cv::Mat(size, size, CV_8U, cv::Scalar(0));
  auto to_px = [&](cv::Vec2f uv) {
    return cv::Vec2d((uv[0] - uv_lo[0]) / (uv_hi[0] - uv_lo[0]) * size,
                     (uv_hi[1] - uv[1]) / (uv_hi[1] - uv_lo[1]) * size);  // v up -> rows down
  };
  for (const auto& poly : model.polygons()) {
    bool face = true;
    for (const auto& c : poly)
      face = face && c.vertex < IctFaceModel::kFaceVertexCount && c.texcoord >= 0;
    if (!face) continue;
    for (size_t k = 1; k + 1 < poly.size(); ++k) {
      const IctFaceModel::Corner tri[3] = {poly[0], poly[k], poly[k + 1]};
      cv::Vec2d p[3];
      for (int j = 0; j < 3; ++j) p[j] = to_px(model.texcoords()[tri[j].texcoord]);
      const double area = (p[1] - p[0])[0] * (p[2] - p[0])[1] - (p[1] - p[0])[1] * (p[2] - p[0])[0];
      if (std::abs(area) < 1e-12) continue;
      const int x0 =
          std::max(0, static_cast<int>(std::floor(std::min({p[0][0], p[1][0], p[2][0]}))));
      const int x1 =
          std::min(size - 1, static_cast<int>(std::ceil(std::max({p[0][0], p[1][0], p[2][0]}))));
      const int y0 =
          std::max(0, static_cast<int>(std::floor(std::min({p[0][1], p[1][1], p[2][1]}))));
      const int y1 =
          std::min(size - 1, static_cast<int>(std::ceil(std::max({p[0][1], p[1][1], p[2][1]}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const cv::Vec2d q(x + 0.5, y + 0.5);
          double b[3];
          for (int j = 0; j < 3; ++j) {
            const cv::Vec2d a = p[(j + 1) % 3] - q, c = p[(j + 2) % 3] - q;
            b[j] = (a[0] * c[1] - a[1] * c[0]) / area;
          }
          if (b[0] < -1e-9 || b[1] < -1e-9 || b[2] < -1e-9) continue;
          cv::Vec3d v(0, 0, 0);
          for (int j = 0; j < 3; ++j) v += b[j] * xyz_mm[tri[j].vertex];
          image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(v);
          image.domain_mask.at<uint8_t>(y, x) = 255;
        }
    }
  }
  return image;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s ICT_DIR OUT_DIR [SIZE=320] [FRAMES=24]\n", argv[0]);
    return 2;
  }
  const int size = argc > 3 ? std::atoi(argv[3]) : 320;
  const int frames = argc > 4 ? std::atoi(argv[4]) : 24;
  auto model = IctFaceModel::load(
      argv[1], {"jawOpen", "mouthSmile_L", "mouthSmile_R", "eyeBlink_L", "eyeBlink_R"});
  if (!model.is_ok()) {
    std::fprintf(stderr, "error: %s\n", model.status().message().c_str());
    return 1;
  }
  cv::Vec2f lo(1e9f, 1e9f), hi(-1e9f, -1e9f);
  for (const auto& poly : model->polygons())
    for (const auto& c : poly)
      if (c.vertex < IctFaceModel::kFaceVertexCount && c.texcoord >= 0)
        for (int k = 0; k < 2; ++k)
          lo[k] = std::min(lo[k], model->texcoords()[c.texcoord][k]),
          hi[k] = std::max(hi[k], model->texcoords()[c.texcoord][k]);
  if (!ensure_directory(argv[2]).is_ok()) return 1;
  for (int i = 0; i < frames; ++i) {
    const double t = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
    const double jaw = 0.6 * std::sin(M_PI * t),
                 smile = 0.8 * std::sin(M_PI * t) * std::sin(M_PI * t);
    const double blink = std::exp(-std::pow((t - 0.5) / 0.06, 2));
    const auto xyz = model->evaluate({{"jawOpen", jaw},
                                      {"mouthSmile_L", smile},
                                      {"mouthSmile_R", smile},
                                      {"eyeBlink_L", blink},
                                      {"eyeBlink_R", blink}});
    GeometryImage image = rasterize(*model, xyz, size, lo, hi);
    image.index = i;
    const Status s = write_geometry_image_exr(frame_path(argv[2], i, ".exr"), image);
    if (!s.is_ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
  }
  if (!write_json(std::filesystem::path(argv[2]) / "stats.json",
                  {{"source", "ICT-FaceKit face area, UV layout"},
                   {"options", {{"fps", 30}, {"size", size}, {"frames", frames}}}})
           .is_ok())
    return 1;
  std::printf("wrote %d frames of %dx%d to %s\n", frames, size, size, argv[2]);
  return 0;
}
