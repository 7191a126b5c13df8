#include "gvkit/capture/phase_shift.hpp"

#include <cmath>

#include "gvkit/core/status.hpp"

namespace gvkit::capture {
namespace {

double type_max(const cv::Mat& image) { return image.depth() == CV_16U ? 65535.0 : 255.0; }

WrappedPhase allocate(cv::Size size) {
  WrappedPhase out;
  out.phase.create(size, CV_32F);
  out.modulation.create(size, CV_32F);
  out.mean.create(size, CV_32F);
  out.saturated.create(size, CV_8U);
  return out;
}

template <typename T>
void decode_rows(const std::vector<cv::Mat>& images, int first, int steps, double saturation_level,
                 WrappedPhase& out) {
  const float scale = static_cast<float>(1.0 / type_max(images[first]));
  const T saturation = static_cast<T>(std::ceil(saturation_level * type_max(images[first])));
  std::vector<float> sin_k(steps), cos_k(steps);
  for (int k = 0; k < steps; ++k) {
    sin_k[k] = static_cast<float>(std::sin(2 * CV_PI * k / steps));
    cos_k[k] = static_cast<float>(std::cos(2 * CV_PI * k / steps));
  }
  const float amp_scale = 2.0f / static_cast<float>(steps) * scale;
  const float mean_scale = scale / static_cast<float>(steps);
  std::vector<const T*> rows(steps);
  std::vector<float> s_row(out.phase.cols), c_row(out.phase.cols);
  for (int y = 0; y < out.phase.rows; ++y) {
    for (int k = 0; k < steps; ++k) rows[k] = images[first + k].ptr<T>(y);
    float* phase = out.phase.ptr<float>(y);
    float* modulation = out.modulation.ptr<float>(y);
    float* mean = out.mean.ptr<float>(y);
    uint8_t* saturated = out.saturated.ptr<uint8_t>(y);
    if (steps == 3) {
      // sin(2pi k/3) = {0, s, -s}, cos = {1, -1/2, -1/2}. Separate simple loops vectorize.
      const float s3 = 0.8660254f;
      const T* r0 = rows[0];
      const T* r1 = rows[1];
      const T* r2 = rows[2];
      float* sv = s_row.data();
      float* cv = c_row.data();
      const int w = out.phase.cols;
      for (int x = 0; x < w; ++x) {
        const float i0 = r0[x], i1 = r1[x], i2 = r2[x];
        sv[x] = s3 * (i1 - i2);
        cv[x] = i0 - 0.5f * (i1 + i2);
        mean[x] = mean_scale * (i0 + i1 + i2);
      }
      for (int x = 0; x < w; ++x) phase[x] = fast_atan2(sv[x], cv[x]);
      for (int x = 0; x < w; ++x) modulation[x] = sv[x] * sv[x] + cv[x] * cv[x];
      for (int x = 0; x < w; ++x) modulation[x] = amp_scale * std::sqrt(modulation[x]);
      for (int x = 0; x < w; ++x)
        saturated[x] =
            (r0[x] >= saturation) | (r1[x] >= saturation) | (r2[x] >= saturation) ? 255 : 0;
      continue;
    }
    for (int x = 0; x < out.phase.cols; ++x) {
      float s = 0, c = 0, sum = 0;
      bool sat = false;
      for (int k = 0; k < steps; ++k) {
        const T v = rows[k][x];
        sat = sat || v >= saturation;
        const float f = v;
        s += f * sin_k[k];
        c += f * cos_k[k];
        sum += f;
      }
      phase[x] = fast_atan2(s, c);
      modulation[x] = amp_scale * std::sqrt(s * s + c * c);
      mean[x] = mean_scale * sum;
      saturated[x] = sat ? 255 : 0;
    }
  }
}

}  // namespace

WrappedPhase decode_phase_shift(const std::vector<cv::Mat>& images, int first, int steps,
                                double saturation_level) {
  GVKIT_CHECK(steps >= 3 && first >= 0 && first + steps <= static_cast<int>(images.size()));
  WrappedPhase out = allocate(images[first].size());
  if (images[first].depth() == CV_16U)
    decode_rows<uint16_t>(images, first, steps, saturation_level, out);
  else
    decode_rows<uint8_t>(images, first, steps, saturation_level, out);
  return out;
}

WrappedPhase decode_phase_shift_reference(const std::vector<cv::Mat>& images, int first, int steps,
                                          double saturation_level) {
  GVKIT_CHECK(steps >= 3 && first >= 0 && first + steps <= static_cast<int>(images.size()));
  WrappedPhase out = allocate(images[first].size());
  const double range = type_max(images[first]);
  for (int y = 0; y < out.phase.rows; ++y)
    for (int x = 0; x < out.phase.cols; ++x) {
      double s = 0, c = 0, sum = 0;
      bool sat = false;
      for (int k = 0; k < steps; ++k) {
        const cv::Mat& image = images[first + k];
        const double v =
            (image.depth() == CV_16U ? image.at<uint16_t>(y, x) : image.at<uint8_t>(y, x)) / range;
        sat = sat || v >= saturation_level - 1e-12;
        const double delta = 2 * CV_PI * k / steps;
        s += v * std::sin(delta);
        c += v * std::cos(delta);
        sum += v;
      }
      out.phase.at<float>(y, x) = static_cast<float>(std::atan2(s, c));
      out.modulation.at<float>(y, x) = static_cast<float>(2.0 / steps * std::hypot(s, c));
      out.mean.at<float>(y, x) = static_cast<float>(sum / steps);
      out.saturated.at<uint8_t>(y, x) = sat ? 255 : 0;
    }
  return out;
}

}  // namespace gvkit::capture
