// Reconstruction speed and phase accuracy on the synthetic ICT face, ours against OpenCV contrib
// (structured_light::SinusoidalPattern PSP + phase_unwrapping::HistogramPhaseUnwrapping) from the
// same 3-step images, single-threaded. After the Google Benchmark timings, a summary prints the
// phase errors against ground truth and the speed ratio.
//   capture_reconstruct_benchmark [--benchmark_filter=...]
// Needs ../shared/data/ict-facekit (or GVKIT_SHARED_DATA).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/phase_unwrapping.hpp>
#include <opencv2/structured_light.hpp>

#include "gvkit/capture/ict_face_scene.hpp"
#include "gvkit/capture/phase_shift.hpp"
#include "gvkit/capture/phase_unwrapping.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/scan_accuracy.hpp"
#include "gvkit/capture/synthetic_rig.hpp"

namespace gvkit::capture {
namespace {

constexpr double kNoise = 0.01;  // camera noise, fraction of the range

struct Case {
  Calibration calibration;
  std::unique_ptr<PatternSet> patterns;
  FringeSet fringes;
  SyntheticTruth truth;
  SyntheticScene scene;
  cv::Mat true_phase;  // CV_32F, 2 pi u / pitch of the lit surface point, NaN elsewhere
  std::optional<Reconstructor> reconstructor;
};

const IctFaceScene* face() {
  static std::unique_ptr<IctFaceScene> scene = [] {
    const char* env = std::getenv("GVKIT_SHARED_DATA");
    const std::filesystem::path dir = env ? env : GVKIT_SHARED_DATA_DIR;
    auto s = IctFaceScene::load(dir / "ict-facekit");
    if (!s) {
      std::fprintf(stderr, "cannot load the ICT face: %s\n", s.status().message().c_str());
      std::exit(1);
    }
    return std::make_unique<IctFaceScene>(std::move(*s));
  }();
  return scene.get();
}

Case& get_case(int width, int height) {
  static std::map<std::pair<int, int>, std::unique_ptr<Case>> cases;
  auto& slot = cases[{width, height}];
  if (slot) return *slot;
  slot = std::make_unique<Case>();
  Case& c = *slot;
  SyntheticRigOptions rig;
  rig.camera_width = width;
  rig.camera_height = height;
  c.calibration = synthetic_calibration(rig);
  c.patterns = std::move(create_pattern_set("psp3-f16").value());
  RenderOptions render;
  render.noise_sigma = kNoise;
  const SyntheticRenderer renderer(c.calibration, render);
  auto track = ExpressionTrack::create("neutral", 1).value();
  c.scene = face()->scene(track.at(0));
  const SyntheticFrame frame = renderer.render(
      c.scene,
      c.patterns->generate({c.calibration.projector_width, c.calibration.projector_height}), 7);
  c.fringes.images = frame.images;
  c.truth = frame.truth;
  c.reconstructor.emplace(std::move(Reconstructor::create(c.calibration).value()));
  // True phase: project the true point into the projector.
  const double pitch = c.patterns->pitch_px(c.calibration.projector_width);
  cv::Vec3d rvec;
  cv::Rodrigues(c.calibration.R_proj_from_cam(), rvec);
  c.true_phase = cv::Mat(height, width, CV_32F, cv::Scalar(NAN));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (!frame.truth.lit.at<uint8_t>(y, x)) continue;
      std::vector<cv::Point3d> p{cv::Point3d(cv::Vec3d(frame.truth.xyz_mm.at<cv::Vec3f>(y, x)))};
      std::vector<cv::Point2d> q;
      cv::projectPoints(p, rvec, c.calibration.t_proj_from_cam_mm(), c.calibration.projector_K,
                        c.calibration.projector_dist, q);
      c.true_phase.at<float>(y, x) = static_cast<float>(2 * CV_PI * q[0].x / pitch);
    }
  return c;
}

// OpenCV contrib: PSP wrapped phase + histogram unwrapping. Returns the unwrapped map.
struct OpenCvResult {
  cv::Mat wrapped, unwrapped, mask;
};
OpenCvResult opencv_psp(const Case& c) {
  auto params = cv::makePtr<cv::structured_light::SinusoidalPattern::Params>();
  params->width = c.calibration.projector_width;
  params->height = c.calibration.projector_height;
  params->nbrOfPeriods = 16;
  params->shiftValue = static_cast<float>(2 * CV_PI / 3);
  params->methodId = cv::structured_light::PSP;
  params->horizontal = false;
  params->setMarkers = false;
  auto psp = cv::structured_light::SinusoidalPattern::create(params);
  OpenCvResult r;
  psp->computePhaseMap(c.fringes.images, r.wrapped, r.mask);
  cv::phase_unwrapping::HistogramPhaseUnwrapping::Params hp;
  hp.width = c.fringes.images[0].cols;
  hp.height = c.fringes.images[0].rows;
  auto unwrapping = cv::phase_unwrapping::HistogramPhaseUnwrapping::create(hp);
  unwrapping->unwrapPhaseMap(r.wrapped, r.unwrapped, r.mask);
  return r;
}

void BM_Gvkit3Step(benchmark::State& state) {
  cv::setNumThreads(1);
  Case& c = get_case(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    auto scan = c.reconstructor->reconstruct(c.fringes, *c.patterns);
    benchmark::DoNotOptimize(scan);
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Gvkit3Step)->Args({512, 512})->Args({640, 480})->Unit(benchmark::kMillisecond);

// The plain reference kernels: std::atan2 decode, exact priority-queue unwrapping, per-pixel
// OpenCV triangulation.
void BM_Gvkit3StepReference(benchmark::State& state) {
  cv::setNumThreads(1);
  Case& c = get_case(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  PatternSetOptions po;
  po.reference = true;
  auto patterns = create_pattern_set("psp3-f16", po).value();
  ReconstructOptions ro;
  ro.reference = true;
  auto reconstructor = Reconstructor::create(c.calibration, ro).value();
  for (auto _ : state) {
    auto scan = reconstructor.reconstruct(c.fringes, *patterns);
    benchmark::DoNotOptimize(scan);
  }
}
BENCHMARK(BM_Gvkit3StepReference)->Args({512, 512})->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_GvkitDecode(benchmark::State& state) {
  Case& c = get_case(512, 512);
  for (auto _ : state) benchmark::DoNotOptimize(decode_phase_shift(c.fringes.images, 0, 3, 0.995));
}
BENCHMARK(BM_GvkitDecode)->Unit(benchmark::kMillisecond);

void BM_GvkitUnwrap(benchmark::State& state) {
  Case& c = get_case(512, 512);
  const WrappedPhase w = decode_phase_shift(c.fringes.images, 0, 3, 0.995);
  cv::Mat valid0 = w.modulation >= 0.02;
  for (auto _ : state) {
    cv::Mat valid = valid0.clone();
    benchmark::DoNotOptimize(unwrap_quality_guided(w.phase, w.modulation, valid, 64));
  }
}
BENCHMARK(BM_GvkitUnwrap)->Unit(benchmark::kMillisecond);

void BM_GvkitTriangulate(benchmark::State& state) {
  Case& c = get_case(512, 512);
  const cv::Mat u = c.true_phase * (c.patterns->pitch_px(912) / (2 * CV_PI));
  for (auto _ : state) benchmark::DoNotOptimize(c.reconstructor->triangulate_columns(u));
}
BENCHMARK(BM_GvkitTriangulate)->Unit(benchmark::kMillisecond);

void BM_OpenCvPspHistogram(benchmark::State& state) {
  cv::setNumThreads(1);
  Case& c = get_case(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(opencv_psp(c));
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OpenCvPspHistogram)->Args({512, 512})->Args({640, 480})->Unit(benchmark::kMillisecond);

// Phase error against the truth over lit pixels valid in `valid`: the wrapped error after
// removing the best constant offset and sign (RMS, rad), and the share of pixels whose unwrapped
// phase is within pi of the dominant offset (correctly unwrapped).
struct PhaseError {
  double wrapped_rms = 0, unwrapped_ok = 0;
  int pixels = 0;
};
PhaseError phase_error(const cv::Mat& wrapped, const cv::Mat& unwrapped, const cv::Mat& valid,
                       const cv::Mat& truth) {
  PhaseError best;
  best.wrapped_rms = INFINITY;
  for (int sign : {1, -1}) {
    double sx = 0, sy = 0;
    std::vector<double> unwrap_offsets;
    for (int y = 0; y < truth.rows; ++y)
      for (int x = 0; x < truth.cols; ++x) {
        const float t = truth.at<float>(y, x), w = wrapped.at<float>(y, x);
        if (std::isnan(t) || !valid.at<uint8_t>(y, x) || std::isnan(w)) continue;
        const double d = w - sign * t;
        sx += std::cos(d);
        sy += std::sin(d);
        const float u = unwrapped.at<float>(y, x);
        if (std::isfinite(u)) unwrap_offsets.push_back(u - sign * t);
      }
    const double offset = std::atan2(sy, sx);
    double sum2 = 0;
    int n = 0;
    for (int y = 0; y < truth.rows; ++y)
      for (int x = 0; x < truth.cols; ++x) {
        const float t = truth.at<float>(y, x), w = wrapped.at<float>(y, x);
        if (std::isnan(t) || !valid.at<uint8_t>(y, x) || std::isnan(w)) continue;
        const double d = std::remainder(w - sign * t - offset, 2 * CV_PI);
        sum2 += d * d;
        ++n;
      }
    const double rms = n ? std::sqrt(sum2 / n) : INFINITY;
    if (rms < best.wrapped_rms) {
      best.wrapped_rms = rms;
      best.pixels = n;
      if (!unwrap_offsets.empty()) {
        std::vector<double> sorted = unwrap_offsets;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        const double median = sorted[sorted.size() / 2];
        int ok = 0;
        for (double o : unwrap_offsets) ok += std::abs(o - median) < CV_PI;
        best.unwrapped_ok = static_cast<double>(ok) / unwrap_offsets.size();
      }
    }
  }
  return best;
}

template <typename F>
double median_ms(F f, int runs) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

void print_summary() {
  cv::setNumThreads(1);
  std::printf("\nSummary (single-threaded, same 3-step images, noise %.0f %%):\n", kNoise * 100);
  std::printf("%-9s %-28s %9s %8s %13s %12s %12s\n", "size", "method", "ms/frame", "fps",
              "wrapped rms", "unwrap ok", "depth rms");
  for (auto [w, h] : {std::pair{512, 512}, std::pair{640, 480}}) {
    Case& c = get_case(w, h);
    // Ours.
    std::optional<RangeScan> scan;
    const double ours_ms = median_ms(
        [&] { scan = std::move(c.reconstructor->reconstruct(c.fringes, *c.patterns).value()); },
        30);
    PhaseMap map = c.patterns->decode(c.fringes, c.calibration.projector_width).value();
    const WrappedPhase w3 = decode_phase_shift(c.fringes.images, 0, 3, 0.995);
    // Unwrapped check for ours: the absolute phase of the scan's points.
    cv::Mat ours_abs(h, w, CV_32F, cv::Scalar(NAN));
    {
      cv::Vec3d rvec;
      cv::Rodrigues(c.calibration.R_proj_from_cam(), rvec);
      const double pitch = c.patterns->pitch_px(c.calibration.projector_width);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          if (!scan->valid.at<uint8_t>(y, x)) continue;
          std::vector<cv::Point3d> p{cv::Point3d(cv::Vec3d(scan->xyz_mm.at<cv::Vec3f>(y, x)))};
          std::vector<cv::Point2d> q;
          cv::projectPoints(p, rvec, c.calibration.t_proj_from_cam_mm(), c.calibration.projector_K,
                            c.calibration.projector_dist, q);
          ours_abs.at<float>(y, x) = static_cast<float>(2 * CV_PI * q[0].x / pitch);
        }
    }
    const PhaseError ours = phase_error(w3.phase, ours_abs, map.valid, c.true_phase);
    const ScanAccuracy acc = scan_accuracy(*scan, ground_truth_of(c.truth, c.scene));
    // OpenCV.
    OpenCvResult cv_result;
    double cv_ms = NAN;
    try {
      cv_ms = median_ms([&] { cv_result = opencv_psp(c); }, 5);
    } catch (const cv::Exception& e) {
      std::printf("OpenCV failed at %dx%d: %s\n", w, h, e.what());
      continue;
    }
    cv::Mat cv_valid =
        cv_result.mask.empty() ? cv::Mat(h, w, CV_8U, cv::Scalar(255)) : (cv_result.mask != 0);
    cv::Mat cv_wrapped, cv_unwrapped;
    cv_result.wrapped.convertTo(cv_wrapped, CV_32F);
    cv_result.unwrapped.convertTo(cv_unwrapped, CV_32F);
    const PhaseError peer = phase_error(cv_wrapped, cv_unwrapped, cv_valid, c.true_phase);
    char size[16];
    std::snprintf(size, sizeof(size), "%dx%d", w, h);
    std::printf("%-9s %-28s %9.2f %8.1f %9.4f rad %11.4f %9.3f mm\n", size,
                "gvkit psp3-f16 (+triang.)", ours_ms, 1000 / ours_ms, ours.wrapped_rms,
                ours.unwrapped_ok, acc.face_interior_rms_mm);
    std::printf("%-9s %-28s %9.2f %8.1f %9.4f rad %11.4f %12s\n", size, "OpenCV PSP + histogram",
                cv_ms, 1000 / cv_ms, peer.wrapped_rms, peer.unwrapped_ok, "n/a");
    std::printf("%-9s speed ratio gvkit / OpenCV: %.1fx\n", size, cv_ms / ours_ms);
  }
}

}  // namespace
}  // namespace gvkit::capture

int main(int argc, char** argv) {
  ::benchmark::Initialize(&argc, argv);
  if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  ::benchmark::RunSpecifiedBenchmarks();
  ::benchmark::Shutdown();
  gvkit::capture::print_summary();
  return 0;
}
