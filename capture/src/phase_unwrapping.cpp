#include "gvkit/capture/phase_unwrapping.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit::capture {
namespace {

constexpr float kTwoPi = 6.28318530718f;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Neighbours whose wrapped phases differ by more than this are not unwrapped against each other:
// such a jump is as likely a steep slope or a depth edge as it is fringe.
constexpr float kMaxJump = 0.6f * 3.14159265f;

// Nearest integer of a small float by truncation (one instruction on baseline x86-64, where
// std::nearbyint is a library call); ties go away from zero.
inline float round_small(float x) {
  return static_cast<float>(static_cast<int>(x + (x >= 0 ? 0.5f : -0.5f)));
}

inline float unwrap_against(float wrapped, float reference) {
  return wrapped + kTwoPi * round_small((reference - wrapped) * (1.0f / kTwoPi));
}

void check_inputs(const cv::Mat& wrapped, const cv::Mat& quality, const cv::Mat& valid) {
  GVKIT_CHECK(wrapped.type() == CV_32F && quality.type() == CV_32F && valid.type() == CV_8U);
  GVKIT_CHECK(wrapped.size() == quality.size() && wrapped.size() == valid.size());
  GVKIT_CHECK(wrapped.isContinuous() && quality.isContinuous() && valid.isContinuous());
}

// Clears regions smaller than min_region_px (pixels listed region by region in `order`).
void drop_small_regions(const std::vector<int>& order, const std::vector<int>& starts,
                        int min_region_px, SpatialUnwrap& out, cv::Mat& valid) {
  float* phase = out.phase.ptr<float>();
  int* region = out.region.ptr<int>();
  uint8_t* ok = valid.ptr<uint8_t>();
  int next_label = 0;
  for (size_t r = 0; r + 1 < starts.size(); ++r) {
    const int begin = starts[r], end = starts[r + 1];
    if (end - begin < min_region_px) {
      for (int i = begin; i < end; ++i) {
        phase[order[i]] = kNaN;
        region[order[i]] = 0;
        ok[order[i]] = 0;
      }
    } else {
      ++next_label;
      for (int i = begin; i < end; ++i) region[order[i]] = next_label;
    }
  }
  out.region_count = next_label;
}

SpatialUnwrap allocate(cv::Size size) {
  SpatialUnwrap out;
  out.phase = cv::Mat(size, CV_32F, cv::Scalar(kNaN));
  out.region = cv::Mat(size, CV_32S, cv::Scalar(0));
  return out;
}

}  // namespace

SpatialUnwrap unwrap_quality_guided(const cv::Mat& wrapped, const cv::Mat& quality, cv::Mat& valid,
                                    int min_region_px) {
  check_inputs(wrapped, quality, valid);
  const int w = wrapped.cols, h = wrapped.rows, n = w * h;
  SpatialUnwrap out = allocate(wrapped.size());
  const float* wr = wrapped.ptr<float>();
  const float* q = quality.ptr<float>();
  uint8_t* ok = valid.ptr<uint8_t>();
  float* phase = out.phase.ptr<float>();

  constexpr int kBuckets = 64;
  float q_max = 0;
  for (int i = 0; i < n; ++i)
    if (ok[i]) q_max = std::max(q_max, q[i]);
  if (q_max <= 0) {
    valid.setTo(0);
    return out;
  }
  const float to_bucket = (kBuckets - 1e-3f) / q_max;
  std::vector<uint8_t> bucket(n);
  for (int i = 0; i < n; ++i)
    bucket[i] = static_cast<uint8_t>(std::clamp(q[i] * to_bucket, 0.0f, kBuckets - 1.0f));
  auto bucket_of = [&](int i) { return static_cast<int>(bucket[i]); };
  // Usable links to the 4 neighbours (bit 0 left, 1 right, 2 up, 3 down): both pixels valid and
  // the wrapped jump small. The jump does not depend on the path (phase[p] = wrapped[p] + 2 pi k).
  std::vector<uint8_t> links(n, 0);
  auto small_jump = [&](int a, int b) {
    const float d = std::fabs(wr[b] - wr[a]);  // in [0, 2 pi): the wrapped jump is min(d, 2pi-d)
    return d <= kMaxJump || kTwoPi - d <= kMaxJump;
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (!ok[i]) continue;
      if (x + 1 < w && ok[i + 1] && small_jump(i, i + 1)) {
        links[i] |= 2;
        links[i + 1] |= 1;
      }
      if (y + 1 < h && ok[i + w] && small_jump(i, i + w)) {
        links[i] |= 8;
        links[i + w] |= 4;
      }
    }

  // Seeds in descending quality bucket (counting sort).
  std::vector<int> count(kBuckets + 1, 0);
  for (int i = 0; i < n; ++i)
    if (ok[i]) ++count[bucket_of(i)];
  std::vector<int> seed_start(kBuckets + 1, 0);
  for (int b = kBuckets - 1; b >= 0; --b) seed_start[b] = seed_start[b + 1] + count[b + 1];
  // seed_start[b] = number of pixels in buckets above b.
  std::vector<int> seeds(seed_start[0] + count[0]);
  {
    std::vector<int> fill = seed_start;
    for (int i = 0; i < n; ++i)
      if (ok[i]) seeds[fill[bucket_of(i)]++] = i;
  }

  std::vector<std::vector<int>> buckets(kBuckets);
  for (auto& b : buckets) b.reserve(1024);
  std::vector<int> order;
  order.reserve(seeds.size());
  std::vector<int> starts;
  std::vector<uint8_t> visited(n, 0);  // region labels are set by drop_small_regions
  for (int seed : seeds) {
    if (visited[seed]) continue;
    starts.push_back(static_cast<int>(order.size()));
    visited[seed] = 1;
    phase[seed] = wr[seed];
    int top = bucket_of(seed);
    buckets[top].push_back(seed);
    while (true) {
      while (top >= 0 && buckets[top].empty()) --top;
      if (top < 0) break;
      const int p = buckets[top].back();
      buckets[top].pop_back();
      order.push_back(p);
      const int neighbours[4] = {p - 1, p + 1, p - w, p + w};
      const uint8_t link = links[p];
      for (int d = 0; d < 4; ++d) {
        const int nb = neighbours[d];
        if (!(link & (1 << d)) || visited[nb]) continue;
        visited[nb] = 1;
        phase[nb] = unwrap_against(wr[nb], phase[p]);
        const int b = bucket_of(nb);
        buckets[b].push_back(nb);
        top = std::max(top, b);
      }
    }
  }
  starts.push_back(static_cast<int>(order.size()));
  drop_small_regions(order, starts, min_region_px, out, valid);
  return out;
}

SpatialUnwrap unwrap_quality_guided_reference(const cv::Mat& wrapped, const cv::Mat& quality,
                                              cv::Mat& valid, int min_region_px) {
  check_inputs(wrapped, quality, valid);
  const int w = wrapped.cols, h = wrapped.rows, n = w * h;
  SpatialUnwrap out = allocate(wrapped.size());
  std::vector<int> seeds;
  for (int i = 0; i < n; ++i)
    if (valid.ptr<uint8_t>()[i]) seeds.push_back(i);
  const float* q = quality.ptr<float>();
  std::stable_sort(seeds.begin(), seeds.end(), [&](int a, int b) { return q[a] > q[b]; });
  std::vector<char> visited(n, 0);
  std::vector<int> order, starts;
  for (int seed : seeds) {
    if (visited[seed]) continue;
    starts.push_back(static_cast<int>(order.size()));
    visited[seed] = 1;
    out.phase.ptr<float>()[seed] = wrapped.ptr<float>()[seed];
    std::priority_queue<std::pair<float, int>> queue;
    queue.push({q[seed], seed});
    while (!queue.empty()) {
      const int p = queue.top().second;
      queue.pop();
      order.push_back(p);
      const int px = p % w, py = p / w;
      for (auto [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
        const int nx = px + dx, ny = py + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int nb = ny * w + nx;
        if (visited[nb] || !valid.ptr<uint8_t>()[nb]) continue;
        const float unwrapped = unwrap_against(wrapped.ptr<float>()[nb], out.phase.ptr<float>()[p]);
        if (std::fabs(unwrapped - out.phase.ptr<float>()[p]) > kMaxJump) continue;
        visited[nb] = 1;
        out.phase.ptr<float>()[nb] = unwrapped;
        queue.push({q[nb], nb});
      }
    }
  }
  starts.push_back(static_cast<int>(order.size()));
  drop_small_regions(order, starts, min_region_px, out, valid);
  return out;
}

cv::Mat unwrap_temporal(const cv::Mat& coarse_absolute, double ratio, const cv::Mat& fine_wrapped,
                        double tolerance, cv::Mat& valid, cv::Mat* uncertain) {
  if (uncertain && uncertain->empty()) *uncertain = cv::Mat(valid.size(), CV_8U, cv::Scalar(0));
  GVKIT_CHECK(coarse_absolute.type() == CV_32F && fine_wrapped.type() == CV_32F &&
              valid.type() == CV_8U);
  cv::Mat out(fine_wrapped.size(), CV_32F);
  const float r = static_cast<float>(ratio), tol = static_cast<float>(tolerance);
  for (int y = 0; y < out.rows; ++y) {
    const float* coarse = coarse_absolute.ptr<float>(y);
    const float* fine = fine_wrapped.ptr<float>(y);
    float* abs = out.ptr<float>(y);
    uint8_t* ok = valid.ptr<uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      const float periods = (coarse[x] * r - fine[x]) / kTwoPi;
      const float k = std::nearbyint(periods);
      const bool certain = std::fabs(periods - k) <= tol;
      if (!ok[x] || !std::isfinite(periods) || (!certain && !uncertain)) {
        ok[x] = 0;
        abs[x] = kNaN;
        continue;
      }
      if (!certain) uncertain->at<uint8_t>(y, x) = 255;
      abs[x] = fine[x] + kTwoPi * k;
    }
  }
  return out;
}

int correct_period_order(cv::Mat& absolute, const cv::Mat& valid) {
  GVKIT_CHECK(absolute.type() == CV_32F && valid.type() == CV_8U &&
              absolute.size() == valid.size());
  const int w = absolute.cols, h = absolute.rows;
  const float pi = kTwoPi / 2;
  const cv::Mat source = absolute.clone();
  int corrected = 0;
  float window[25];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!valid.at<uint8_t>(y, x)) continue;
      const float phi = source.at<float>(y, x);
      int agree = 0, neighbours = 0;
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h || !valid.at<uint8_t>(ny[k], nx[k]))
          continue;
        ++neighbours;
        agree += std::fabs(source.at<float>(ny[k], nx[k]) - phi) < pi;
      }
      if (neighbours == 0 || 2 * agree > neighbours) continue;
      int n = 0;
      for (int yy = std::max(0, y - 2); yy <= std::min(h - 1, y + 2); ++yy)
        for (int xx = std::max(0, x - 2); xx <= std::min(w - 1, x + 2); ++xx)
          if (valid.at<uint8_t>(yy, xx)) window[n++] = source.at<float>(yy, xx);
      if (n < 5) continue;
      std::nth_element(window, window + n / 2, window + n);
      const float median = window[n / 2];
      const float moved = phi + kTwoPi * std::nearbyint((median - phi) / kTwoPi);
      if (moved != phi) {
        absolute.at<float>(y, x) = moved;
        ++corrected;
      }
    }
  return corrected;
}

int settle_uncertain(cv::Mat& absolute, cv::Mat& valid, const cv::Mat& uncertain) {
  if (uncertain.empty()) return 0;
  const int w = absolute.cols, h = absolute.rows;
  int kept = 0;
  float window[25];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!uncertain.at<uint8_t>(y, x) || !valid.at<uint8_t>(y, x)) continue;
      int n = 0;
      for (int yy = std::max(0, y - 2); yy <= std::min(h - 1, y + 2); ++yy)
        for (int xx = std::max(0, x - 2); xx <= std::min(w - 1, x + 2); ++xx)
          if (valid.at<uint8_t>(yy, xx) && !uncertain.at<uint8_t>(yy, xx))
            window[n++] = absolute.at<float>(yy, xx);
      float& phi = absolute.at<float>(y, x);
      if (n < 4) {
        phi = kNaN;
        valid.at<uint8_t>(y, x) = 0;
        continue;
      }
      std::nth_element(window, window + n / 2, window + n);
      phi += kTwoPi * std::nearbyint((window[n / 2] - phi) / kTwoPi);
      ++kept;
    }
  return kept;
}

void clear_outside_projector(cv::Mat& absolute, cv::Mat& valid, double pitch_px, int width) {
  const float lo = static_cast<float>(-0.5 / pitch_px * kTwoPi);
  const float hi = static_cast<float>((width - 0.5) / pitch_px * kTwoPi);
  for (int y = 0; y < absolute.rows; ++y) {
    float* a = absolute.ptr<float>(y);
    uint8_t* ok = valid.ptr<uint8_t>(y);
    for (int x = 0; x < absolute.cols; ++x)
      if (ok[x] && !(a[x] >= lo && a[x] <= hi)) {
        ok[x] = 0;
        a[x] = kNaN;
      }
  }
}

cv::Mat absolute_single_period(const cv::Mat& wrapped, const cv::Mat& valid) {
  cv::Mat out(wrapped.size(), CV_32F);
  for (int y = 0; y < out.rows; ++y) {
    const float* w = wrapped.ptr<float>(y);
    const uint8_t* ok = valid.ptr<uint8_t>(y);
    float* abs = out.ptr<float>(y);
    for (int x = 0; x < out.cols; ++x) abs[x] = !ok[x] ? kNaN : (w[x] < 0 ? w[x] + kTwoPi : w[x]);
  }
  return out;
}

}  // namespace gvkit::capture
