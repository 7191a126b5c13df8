#include "gvkit/capture/synthetic_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "gvkit/capture/lens_distortion.hpp"
#include "rasterizer.hpp"

namespace gvkit::capture {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

float bilinear(const cv::Mat& image, float u, float v) {
  const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, image.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, image.rows - 2);
  const float fx = std::clamp(u - x0, 0.0f, 1.0f), fy = std::clamp(v - y0, 0.0f, 1.0f);
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

std::vector<cv::Vec3d> vertex_normals(const SyntheticScene& scene) {
  std::vector<cv::Vec3d> normals(scene.positions_mm.size(), cv::Vec3d(0, 0, 0));
  for (const cv::Vec3i& t : scene.triangles) {
    const cv::Vec3d& a = scene.positions_mm[t[0]];
    const cv::Vec3d n = (scene.positions_mm[t[1]] - a).cross(scene.positions_mm[t[2]] - a);
    for (int k = 0; k < 3; ++k) normals[t[k]] += n;  // area weighted
  }
  for (auto& n : normals) {
    const double len = cv::norm(n);
    if (len > 0) n /= len;
  }
  return normals;
}

}  // namespace

nlohmann::json RenderOptions::to_json() const {
  return {{"ambient", ambient},
          {"projector_power", projector_power},
          {"projector_gamma", projector_gamma},
          {"projector_bit_depth", projector_bit_depth},
          {"projector_blur_px", projector_blur_px},
          {"camera_blur_px", camera_blur_px},
          {"noise_sigma", noise_sigma},
          {"bit_depth", bit_depth}};
}

Status RenderOptions::check() const {
  if (!(ambient >= 0 && ambient <= 1)) return invalid_argument("ambient must be in [0, 1]");
  if (!(projector_power >= 0 && projector_power <= 10))
    return invalid_argument("projector power must be in [0, 10]");
  if (!(projector_gamma >= 0.2 && projector_gamma <= 5))
    return invalid_argument("projector gamma must be in [0.2, 5], is " +
                            std::to_string(projector_gamma));
  if (projector_bit_depth != 0 && (projector_bit_depth < 1 || projector_bit_depth > 16))
    return invalid_argument("projector bit depth must be 0 (none) or 1..16");
  if (!(projector_blur_px >= 0 && projector_blur_px <= 50 && camera_blur_px >= 0 &&
        camera_blur_px <= 50))
    return invalid_argument("blur sigma must be in [0, 50] px");
  if (!(noise_sigma >= 0 && noise_sigma <= 0.5))
    return invalid_argument("noise sigma must be in [0, 0.5] of the range, is " +
                            std::to_string(noise_sigma));
  if (bit_depth != 8 && bit_depth != 10 && bit_depth != 12 && bit_depth != 16)
    return invalid_argument("bit depth must be 8, 10, 12 or 16, is " + std::to_string(bit_depth));
  if (!(shadow_bias_mm >= 0)) return invalid_argument("shadow bias must be >= 0 mm");
  return Status::ok();
}

SyntheticRenderer::SyntheticRenderer(const Calibration& calibration, const RenderOptions& options)
    : calibration_(calibration), options_(options) {
  GVKIT_CHECK(calibration.check().is_ok(), calibration.check().message());
  GVKIT_CHECK(options.check().is_ok(), options.check().message());
  camera_rays_ = detail::pixel_rays(calibration.camera_K, calibration.camera_dist,
                                    {calibration.camera_width, calibration.camera_height});
  projector_rays_ = detail::pixel_rays(calibration.projector_K, calibration.projector_dist,
                                       {calibration.projector_width, calibration.projector_height});
}

SyntheticFrame SyntheticRenderer::render(const SyntheticScene& scene,
                                         const std::vector<cv::Mat>& patterns,
                                         uint64_t seed) const {
  const Calibration& c = calibration_;
  GVKIT_CHECK(scene.albedo.size() == scene.positions_mm.size(), "one albedo per vertex");
  for (const cv::Mat& p : patterns)
    GVKIT_CHECK(p.type() == CV_32F && p.cols == c.projector_width && p.rows == c.projector_height,
                "patterns must be CV_32F of the projector size");
  const cv::Size size(c.camera_width, c.camera_height);

  // What the camera sees, and what the projector lights.
  const detail::DepthBuffer seen = detail::rasterize(scene.positions_mm, scene.triangles,
                                                     camera_rays_, c.camera_K, c.camera_dist);
  const cv::Matx33d R = c.R_proj_from_cam();
  const cv::Vec3d t = c.t_proj_from_cam_mm();
  std::vector<cv::Vec3d> in_projector(scene.positions_mm.size());
  for (size_t i = 0; i < in_projector.size(); ++i) in_projector[i] = R * scene.positions_mm[i] + t;
  const detail::DepthBuffer lit_depth = detail::rasterize(
      in_projector, scene.triangles, projector_rays_, c.projector_K, c.projector_dist);
  const std::vector<cv::Vec3d> normals = vertex_normals(scene);
  LensDistortion projector_lens;
  projector_lens.set(c.projector_dist);

  SyntheticFrame frame;
  SyntheticTruth& truth = frame.truth;
  truth.xyz_mm = cv::Mat(size, CV_32FC3, cv::Scalar::all(kNaN));
  truth.triangle = seen.triangle.clone();
  truth.barycentric = seen.barycentric.clone();
  truth.lit = cv::Mat(size, CV_8U, cv::Scalar(0));
  cv::Mat proj_u(size, CV_32F, cv::Scalar(0)), proj_v(size, CV_32F, cv::Scalar(0));
  cv::Mat gain(size, CV_32F, cv::Scalar(0)), offset(size, CV_32F, cv::Scalar(0));
  const cv::Vec3d projector_centre = c.t_cam_from_proj_mm;
  const cv::Matx33d& Kp = c.projector_K;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const int tri = seen.triangle.at<int>(y, x);
      if (tri < 0) continue;
      const cv::Vec2f ray = camera_rays_.at<cv::Vec2f>(y, x);
      const double z = seen.depth.at<float>(y, x);
      const cv::Vec3d p(ray[0] * z, ray[1] * z, z);
      truth.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(p);
      const cv::Vec3f b = seen.barycentric.at<cv::Vec3f>(y, x);
      const cv::Vec3i& v = scene.triangles[tri];
      cv::Vec3d n = b[0] * normals[v[0]] + b[1] * normals[v[1]] + b[2] * normals[v[2]];
      if (n.dot(p) > 0) n = -n;  // the side facing the camera
      const double n_len = cv::norm(n);
      if (n_len > 0) n /= n_len;
      const float albedo =
          b[0] * scene.albedo[v[0]] + b[1] * scene.albedo[v[1]] + b[2] * scene.albedo[v[2]];
      offset.at<float>(y, x) = static_cast<float>(albedo * options_.ambient);
      const cv::Vec3d to_projector = cv::normalize(projector_centre - p);
      const double cos_p = n.dot(to_projector);
      if (cos_p <= 0) continue;
      const cv::Vec3d q = R * p + t;
      if (q[2] <= 0) continue;
      double xd = q[0] / q[2], yd = q[1] / q[2];
      if (!projector_lens.none) projector_lens.apply(q[0] / q[2], q[1] / q[2], xd, yd);
      const double u = Kp(0, 0) * xd + Kp(0, 1) * yd + Kp(0, 2), vv = Kp(1, 1) * yd + Kp(1, 2);
      if (u < 0 || vv < 0 || u > c.projector_width - 1 || vv > c.projector_height - 1) continue;
      // Shadow test against the projector's depth buffer (the farthest of the 2x2 neighbours,
      // so a surface never shadows itself at grazing angles).
      const int u0 = std::min(static_cast<int>(u), c.projector_width - 2);
      const int v0 = std::min(static_cast<int>(vv), c.projector_height - 2);
      float nearest = 0;
      for (int dv = 0; dv < 2; ++dv)
        for (int du = 0; du < 2; ++du)
          nearest = std::max(nearest, lit_depth.depth.at<float>(v0 + dv, u0 + du));
      if (q[2] > nearest + options_.shadow_bias_mm) continue;
      truth.lit.at<uint8_t>(y, x) = 255;
      proj_u.at<float>(y, x) = static_cast<float>(u);
      proj_v.at<float>(y, x) = static_cast<float>(vv);
      gain.at<float>(y, x) = static_cast<float>(albedo * options_.projector_power * cos_p);
    }

  // Each pattern as the projector emits it: quantized, through its gamma, defocused.
  const double camera_max = options_.bit_depth == 8 ? 255.0 : (1 << options_.bit_depth) - 1.0;
  const double store_scale = options_.bit_depth == 8 ? 255.0 : 65535.0;
  for (size_t k = 0; k < patterns.size(); ++k) {
    cv::Mat emitted = patterns[k].clone();
    if (options_.projector_bit_depth > 0) {
      const double levels = (1 << options_.projector_bit_depth) - 1.0;
      emitted.forEach<float>([&](float& value, const int*) {
        value = static_cast<float>(std::round(std::clamp(value, 0.0f, 1.0f) * levels) / levels);
      });
    }
    if (options_.projector_gamma != 1.0)
      emitted.forEach<float>([&](float& value, const int*) {
        value = static_cast<float>(std::pow(std::max(value, 0.0f), options_.projector_gamma));
      });
    if (options_.projector_blur_px > 0)
      cv::GaussianBlur(emitted, emitted, cv::Size(), options_.projector_blur_px);
    cv::Mat radiance = offset.clone();
    for (int y = 0; y < size.height; ++y) {
      const uint8_t* lit = truth.lit.ptr<uint8_t>(y);
      float* r = radiance.ptr<float>(y);
      for (int x = 0; x < size.width; ++x)
        if (lit[x])
          r[x] += gain.at<float>(y, x) *
                  bilinear(emitted, proj_u.at<float>(y, x), proj_v.at<float>(y, x));
    }
    if (options_.camera_blur_px > 0)
      cv::GaussianBlur(radiance, radiance, cv::Size(), options_.camera_blur_px);
    if (options_.noise_sigma > 0) {
      cv::Mat noise(size, CV_32F);
      cv::RNG rng(seed * 0x9E3779B97F4A7C15ull + k + 1);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.noise_sigma);
      radiance += noise;
    }
    cv::Mat image(size, options_.bit_depth == 8 ? CV_8U : CV_16U);
    for (int y = 0; y < size.height; ++y) {
      const float* r = radiance.ptr<float>(y);
      for (int x = 0; x < size.width; ++x) {
        const double level =
            std::round(std::clamp(static_cast<double>(r[x]), 0.0, 1.0) * camera_max);
        const double stored = std::round(level / camera_max * store_scale);
        if (options_.bit_depth == 8)
          image.at<uint8_t>(y, x) = static_cast<uint8_t>(stored);
        else
          image.at<uint16_t>(y, x) = static_cast<uint16_t>(stored);
      }
    }
    frame.images.push_back(image);
  }
  return frame;
}

}  // namespace gvkit::capture
