#include "geometry_video_material.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>

#include "gvkit/core/ict_face_model.hpp"

namespace gvkit::testing {
namespace {

// Per pixel: the three model vertices and barycentric weights of the UV triangle covering it.
struct PixelSample {
  std::array<int, 3> vertex{-1, -1, -1};
  std::array<double, 3> weight{};
};

std::vector<PixelSample> rasterize_uv(const IctFaceModel& model, int size) {
  std::vector<PixelSample> samples(static_cast<size_t>(size) * size);
  const auto& uv = model.texcoords();
  const auto raster = [&](const IctFaceModel::Corner& a, const IctFaceModel::Corner& b,
                          const IctFaceModel::Corner& c) {
    const std::array<IctFaceModel::Corner, 3> corners{a, b, c};
    double px[3], py[3];
    for (int k = 0; k < 3; ++k) {
      px[k] = uv[corners[k].texcoord][0] * size;
      py[k] = (1.0 - uv[corners[k].texcoord][1]) * size;
    }
    const double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    if (std::abs(area) < 1e-12) return;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({px[0], px[1], px[2]}))));
    const int x1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({px[0], px[1], px[2]}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({py[0], py[1], py[2]}))));
    const int y1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({py[0], py[1], py[2]}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double cx = x + 0.5, cy = y + 0.5;
        double w[3];
        for (int k = 0; k < 3; ++k) {
          const int i = (k + 1) % 3, j = (k + 2) % 3;
          w[k] = ((px[i] - cx) * (py[j] - cy) - (px[j] - cx) * (py[i] - cy)) / area;
        }
        if (w[0] < -1e-9 || w[1] < -1e-9 || w[2] < -1e-9) continue;
        PixelSample& s = samples[static_cast<size_t>(y) * size + x];
        for (int k = 0; k < 3; ++k) {
          s.vertex[k] = corners[k].vertex;
          s.weight[k] = w[k];
        }
      }
  };
  for (const auto& poly : model.polygons()) {
    bool face = poly.size() >= 3;
    for (const auto& c : poly)
      if (c.vertex >= IctFaceModel::kFaceVertexCount || c.texcoord < 0) face = false;
    if (!face) continue;
    for (size_t k = 1; k + 1 < poly.size(); ++k) raster(poly[0], poly[k], poly[k + 1]);
  }
  return samples;
}

std::map<std::string, double> weights_at(double t) {
  const double pi = 3.14159265358979;
  const auto wave = [&](double period, double phase) {
    return 0.5 - 0.5 * std::cos(2 * pi * t / period + phase);
  };
  return {{"jawOpen", 0.8 * wave(2.0, 0)},
          {"mouthSmile_L", 0.7 * wave(3.0, 1.0)},
          {"mouthSmile_R", 0.7 * wave(3.0, 1.3)},
          {"eyeBlink_L", std::pow(wave(1.5, 2.0), 4)},
          {"eyeBlink_R", std::pow(wave(1.5, 2.0), 4)},
          {"browInnerUp_L", 0.6 * wave(2.5, 0.5)},
          {"browInnerUp_R", 0.6 * wave(2.5, 0.5)},
          {"cheekPuff_L", 0.4 * wave(4.0, 2.5)}};
}

}  // namespace

Result<std::vector<GeometryImage>> make_ict_face_video(const std::filesystem::path& ict_dir,
                                                       const GeometryVideoOptions& options) {
  std::vector<std::string> names;
  for (const auto& [name, w] : weights_at(0)) names.push_back(name);
  GVKIT_ASSIGN_OR_RETURN(const IctFaceModel model, IctFaceModel::load(ict_dir, names));
  const int size = options.size;
  const std::vector<PixelSample> samples = rasterize_uv(model, size);
  std::vector<GeometryImage> frames;
  for (int f = 0; f < options.frames; ++f) {
    const double t = f / options.fps;
    const std::vector<cv::Vec3d> positions = model.evaluate(weights_at(t));
    GeometryImage image;
    image.xyz_mm.create(size, size, CV_32FC3);
    image.domain_mask.create(size, size, CV_8U);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const PixelSample& s = samples[static_cast<size_t>(y) * size + x];
        cv::Vec3d p(0, 0, 0);
        if (s.vertex[0] >= 0)
          for (int k = 0; k < 3; ++k) p += s.weight[k] * positions[s.vertex[k]];
        image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(p);
        image.domain_mask.at<uint8_t>(y, x) = s.vertex[0] >= 0 ? 255 : 0;
      }
    image.index = f;
    image.timestamp = Timestamp(static_cast<int64_t>(std::llround(t * 1e9)));
    frames.push_back(std::move(image));
  }
  return frames;
}

std::vector<GeometryImage> make_analytic_video(const GeometryVideoOptions& options) {
  const int size = options.size;
  std::vector<GeometryImage> frames;
  for (int f = 0; f < options.frames; ++f) {
    const double t = f / options.fps;
    GeometryImage image;
    image.xyz_mm.create(size, size, CV_32FC3);
    image.domain_mask.create(size, size, CV_8U);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const double u = (x + 0.5) / size - 0.5, v = (y + 0.5) / size - 0.5;
        const double r2 = u * u / 0.22 + v * v / 0.2;
        const double hole = (u * u) / 0.01 + (v - 0.18) * (v - 0.18) / 0.002;
        const bool inside = r2 < 1.0 && hole > 1.0;
        const double z = 90.0 * std::exp(-r2 * (1.5 + 0.2 * std::sin(2.0 * t))) +
                         3.0 * std::sin(12 * u + 1.5 * t) * std::cos(9 * v);
        image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(
            static_cast<float>(200 * u), static_cast<float>(-240 * v), static_cast<float>(600 - z));
        image.domain_mask.at<uint8_t>(y, x) = inside ? 255 : 0;
      }
    image.index = f;
    image.timestamp = Timestamp(static_cast<int64_t>(std::llround(t * 1e9)));
    frames.push_back(std::move(image));
  }
  return frames;
}

void move_in_picture(std::vector<GeometryImage>* video, double shift_px, double scale_per_frame) {
  for (size_t f = 0; f < video->size(); ++f) {
    GeometryImage& frame = (*video)[f];
    const double shift = shift_px * static_cast<double>(f);
    const double s = 1.0 + scale_per_frame * static_cast<double>(f);
    const double c = frame.xyz_mm.cols / 2.0;
    const double m[6] = {s, 0, -shift + c * (1 - s), 0, s, -0.5 * shift + c * (1 - s)};
    cv::Mat moved;
    cv::warpAffine(frame.xyz_mm, moved, cv::Mat(2, 3, CV_64F, const_cast<double*>(m)),
                   frame.xyz_mm.size(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
    frame.xyz_mm = moved;
  }
}

std::vector<GeometryImage> make_moving_analytic_video(int size, int frames) {
  GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  auto video = make_analytic_video(o);
  move_in_picture(&video, 0.75, 0.01);
  return video;
}

}  // namespace gvkit::testing
