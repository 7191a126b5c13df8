// Player throughput on this machine's OpenGL (llvmpipe offscreen): a 320x320 geometry video
// read from EXR, meshed and drawn at 640x480, stage by stage and as the player pipelines it
// (decode + mesh on the prefetch worker, draw on the calling thread); and seek time.
#include <filesystem>
#include <memory>
#include <random>

#include <benchmark/benchmark.h>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/player/frame_prefetcher.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#ifdef GVKIT_WITH_PLAYER
#include "gvkit/player/renderer.hpp"
#endif
#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

namespace fs = std::filesystem;
constexpr int kSize = 320, kFrames = 24;

// One shared 320x320, 24-frame EXR sequence in the temp folder.
const fs::path& sequence_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / "gvkit_player_bench_seq";
    if (!fs::exists(frame_path(d, kFrames - 1, ".exr")))
      testing::write_face_like_sequence(d, kFrames, kSize);
    return d;
  }();
  return dir;
}

void BM_DecodeExr(benchmark::State& state) {
  auto seq = FrameSequence::create(sequence_dir()).value();
  int64_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(seq->frame(i++ % kFrames).value());
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeExr)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MeshFromGeometryImage(benchmark::State& state) {
  const GeometryImage image = testing::make_face_like_image(kSize, 0);
  size_t triangles = 0;
  for (auto _ : state) triangles = mesh_buffers_from_geometry_image(image).triangle_count();
  state.counters["triangles"] = static_cast<double>(triangles);
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MeshFromGeometryImage)->Unit(benchmark::kMillisecond)->UseRealTime();

// The manifold check of gvkit export's direct writer on a 320x320 frame: the eight-lane check
// (fast:1) against its pairwise reference (fast:0).
void BM_MeshBuffersManifold(benchmark::State& state) {
  const MeshBuffers buffers =
      mesh_buffers_from_geometry_image(testing::make_face_like_image(kSize, 0));
  bool manifold = false;
  for (auto _ : state)
    benchmark::DoNotOptimize(manifold = state.range(0) ? mesh_buffers_manifold(buffers)
                                                       : mesh_buffers_manifold_reference(buffers));
  state.counters["manifold"] = manifold;
}
BENCHMARK(BM_MeshBuffersManifold)->Arg(0)->Arg(1)->ArgName("fast")->Unit(benchmark::kMillisecond);

#ifdef GVKIT_WITH_PLAYER
std::unique_ptr<Renderer> make_renderer(int msaa) {
  RenderOptions options;
  options.msaa_samples = msaa;
  return Renderer::create(options).value();
}

// Upload + draw + read back one mesh (alternating two frames so every upload is real).
void BM_Draw(benchmark::State& state) {
  auto renderer = make_renderer(static_cast<int>(state.range(0)));
  const MeshBuffers a = mesh_buffers_from_geometry_image(testing::make_face_like_image(kSize, 0));
  const MeshBuffers b = mesh_buffers_from_geometry_image(testing::make_face_like_image(kSize, 3));
  ViewCamera camera(scene_frame(a));
  int64_t i = 0;
  for (auto _ : state) {
    renderer->set_mesh(i++ % 2 ? b : a);
    benchmark::DoNotOptimize(renderer->render(camera, {}).value());
  }
  state.SetLabel(renderer->description());
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Draw)->Arg(0)->Arg(4)->ArgName("msaa")->Unit(benchmark::kMillisecond)->UseRealTime();

// Decode + mesh + draw, one after the other on one thread.
void BM_DecodeMeshDrawSerial(benchmark::State& state) {
  auto seq = FrameSequence::create(sequence_dir()).value();
  auto renderer = make_renderer(static_cast<int>(state.range(0)));
  std::unique_ptr<ViewCamera> camera;
  int64_t i = 0;
  for (auto _ : state) {
    const GeometryImage image = seq->frame(i++ % kFrames).value();
    const MeshBuffers mesh = mesh_buffers_from_geometry_image(image);
    if (!camera) camera = std::make_unique<ViewCamera>(scene_frame(mesh));
    renderer->set_mesh(mesh);
    benchmark::DoNotOptimize(renderer->render(*camera, {}).value());
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeMeshDrawSerial)
    ->Arg(0)
    ->Arg(4)
    ->ArgName("msaa")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// As the player runs: decode + mesh on the prefetch worker, upload + draw here.
void BM_DecodeMeshDrawPrefetched(benchmark::State& state) {
  std::shared_ptr<FrameSequence> seq = FrameSequence::create(sequence_dir()).value();
  auto renderer = make_renderer(static_cast<int>(state.range(0)));
  PrefetchOptions options;
  options.mesh.stride = static_cast<int>(state.range(1));
  FramePrefetcher prefetcher(seq, options);
  std::unique_ptr<ViewCamera> camera;
  int64_t i = 0;
  for (auto _ : state) {
    auto frame = prefetcher.get(i++ % kFrames);
    if (!camera) camera = std::make_unique<ViewCamera>(scene_frame(frame->mesh));
    renderer->set_mesh(frame->mesh);
    benchmark::DoNotOptimize(renderer->render(*camera, {}).value());
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeMeshDrawPrefetched)
    ->Args({0, 1})
    ->Args({4, 1})
    ->Args({0, 2})
    ->ArgNames({"msaa", "stride"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
#endif

// Seek: get() of a random frame that is not cached (the worker idle, its window filled
// elsewhere), i.e. decode + mesh of the target, as the player waits for it.
void BM_Seek(benchmark::State& state) {
  std::shared_ptr<FrameSequence> seq = FrameSequence::create(sequence_dir()).value();
  PrefetchOptions options;
  options.ahead = 2;
  options.capacity = 3;
  FramePrefetcher prefetcher(seq, options);
  std::mt19937 rng(1);
  int64_t at = 0;
  for (auto _ : state) {
    state.PauseTiming();
    prefetcher.wait_until_idle();
    int64_t target = at;
    while (std::abs(target - at) < options.capacity + 1) target = rng() % kFrames;
    state.ResumeTiming();
    benchmark::DoNotOptimize(prefetcher.get(target));
    at = target;
  }
}
BENCHMARK(BM_Seek)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gvkit::player
