#include "gvkit/codec/half_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/core.hpp>

namespace gvkit::codec {
namespace {

int padded(int n) { return (n + 15) / 16 * 16; }

// Repeats the last coded column and row into the padding.
void pad_plane(SamplePlane& p, int width, int height) {
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      if (x >= width || y >= height)
        p.at(x, y) = p.at(std::min(x, width - 1), std::min(y, height - 1));
}

// Tap k (0..3) of full-resolution pixel `out` and the half-resolution sample it weighs (clamped
// to [0, n - 1]).
struct Tap {
  int sample, weight;
};
Tap tap(int out, int k, int n) {
  const int i = out / 2;
  if (out % 2 == 1) return {std::clamp(i - 1 + k, 0, n - 1), kHalfUpsampleTaps[k]};
  return {std::clamp(i - 2 + k, 0, n - 1), kHalfUpsampleTaps[3 - k]};
}

// The 1-D upsampling operator as an n_full x half_size(n_full) matrix (weights / 64) and its
// least-squares pseudo-inverse (U^T U)^-1 U^T.
cv::Mat pseudo_inverse(int n_full) {
  const int n = half_size(n_full);
  cv::Mat u = cv::Mat::zeros(n_full, n, CV_64F);
  for (int out = 0; out < n_full; ++out)
    for (int k = 0; k < 4; ++k) {
      const Tap t = tap(out, k, n);
      u.at<double>(out, t.sample) += t.weight / 64.0;
    }
  cv::Mat normal = u.t() * u, inverse;
  cv::invert(normal, inverse, cv::DECOMP_SVD);
  return inverse * u.t();
}

}  // namespace

SamplePlane upsample_half_plane(const SamplePlane& half, int width, int height, int bit_depth) {
  const int w = half_size(width), h = half_size(height);
  GVKIT_CHECK(half.width >= w && half.height >= h);
  std::vector<int32_t> rows(static_cast<size_t>(width) * h);  // horizontal pass, x64
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < width; ++x) {
      int32_t sum = 0;
      for (int k = 0; k < 4; ++k) {
        const Tap t = tap(x, k, w);
        sum += t.weight * half.at(t.sample, y);
      }
      rows[static_cast<size_t>(y) * width + x] = sum;
    }
  SamplePlane out;
  out.width = padded(width);
  out.height = padded(height);
  out.samples.assign(static_cast<size_t>(out.width) * out.height, 0);
  const int64_t max_value = (int64_t{1} << bit_depth) - 1;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int64_t sum = 0;
      for (int k = 0; k < 4; ++k) {
        const Tap t = tap(y, k, h);
        sum += int64_t{t.weight} * rows[static_cast<size_t>(t.sample) * width + x];
      }
      out.at(x, y) = static_cast<uint16_t>(std::clamp<int64_t>((sum + 2048) >> 12, 0, max_value));
    }
  pad_plane(out, width, height);
  return out;
}

SamplePlane downsample_plane(const SamplePlane& full, int width, int height, int bit_depth) {
  const int w = half_size(width), h = half_size(height);
  cv::Mat x(height, width, CV_64F);
  for (int y = 0; y < height; ++y)
    for (int i = 0; i < width; ++i) x.at<double>(y, i) = full.at(i, y);
  const cv::Mat low = pseudo_inverse(height) * x * pseudo_inverse(width).t();  // h x w
  SamplePlane out;
  out.width = padded(w);
  out.height = padded(h);
  out.samples.assign(static_cast<size_t>(out.width) * out.height, 0);
  const double max_value = std::ldexp(1.0, bit_depth) - 1;
  for (int y = 0; y < h; ++y)
    for (int i = 0; i < w; ++i)
      out.at(i, y) =
          static_cast<uint16_t>(std::clamp(std::round(low.at<double>(y, i)), 0.0, max_value));
  pad_plane(out, w, h);
  return out;
}

SamplePlane halve_plane_mean(const SamplePlane& full, int width, int height) {
  const int w = half_size(width), h = half_size(height);
  GVKIT_CHECK(full.width >= width && full.height >= height);
  SamplePlane out;
  out.width = padded(w);
  out.height = padded(h);
  out.samples.assign(static_cast<size_t>(out.width) * out.height, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int x0 = 2 * x, x1 = std::min(2 * x + 1, width - 1);
      const int y0 = 2 * y, y1 = std::min(2 * y + 1, height - 1);
      const uint32_t sum =
          uint32_t{full.at(x0, y0)} + full.at(x1, y0) + full.at(x0, y1) + full.at(x1, y1) + 2;
      out.at(x, y) = static_cast<uint16_t>(sum >> 2);
    }
  pad_plane(out, w, h);
  return out;
}

cv::Mat half_domain_mask(const cv::Mat& mask) {
  cv::Mat half(half_size(mask.rows), half_size(mask.cols), CV_8U, cv::Scalar(0));
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<uint8_t>(y, x)) half.at<uint8_t>(y / 2, x / 2) = 255;
  return half;
}

double domain_mse(const std::vector<SamplePlane>& a, const std::vector<SamplePlane>& b,
                  const cv::Mat& mask) {
  double sum = 0;
  int64_t count = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<uint8_t>(y, x)) {
        ++count;
        for (int p = 0; p < 3; ++p) {
          const double d = static_cast<double>(a[p].at(x, y)) - b[p].at(x, y);
          sum += d * d;
        }
      }
  return count ? sum / (3.0 * static_cast<double>(count)) : 0.0;
}

}  // namespace gvkit::codec
