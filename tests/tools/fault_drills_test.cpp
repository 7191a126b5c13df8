// Fault drills: what a user meets when things go wrong. A truncated and a bit-flipped .gvid
// (the decodable frames are written, the failed ones named), a session folder cut while it was
// written, and out-of-range options for every subcommand (a clear message, exit != 0). A frame
// whose facemap fails inside `gvkit run` is drilled in cli_run_test.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;
namespace fs = std::filesystem;

using testing::contains;

// Encodes `frames` analytic 32x32 frames; returns the stream's bytes and per-frame packet sizes.
struct Stream {
  std::string path;
  std::string bytes;
  std::vector<int64_t> frame_bytes;
  int64_t header_bytes = 0;
};
Stream encode(const TempDir& dir, int frames, const std::string& options) {
  testing::GeometryVideoOptions o;
  o.size = 32;
  o.frames = frames;
  const auto video = testing::make_analytic_video(o);
  EXPECT_TRUE(ensure_directory(dir / "in").is_ok());
  for (size_t i = 0; i < video.size(); ++i)
    EXPECT_TRUE(
        write_geometry_image_exr(frame_path(dir / "in", static_cast<int64_t>(i), ".exr"), video[i])
            .is_ok());
  Stream s;
  s.path = (dir / "v.gvid").string();
  auto r = run_gvkit("encode " + (dir / "in").string() + " -o " + s.path + " " + options);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  s.bytes = read_file(s.path).value();
  auto stats = read_json(s.path + ".stats.json").value();
  int64_t sum = 0;
  for (const auto& f : stats["frames"]) s.frame_bytes.push_back(f["bytes"].get<int64_t>());
  for (int64_t b : s.frame_bytes) sum += b;
  s.header_bytes = stats["summary"]["file_bytes"].get<int64_t>() - sum;
  return s;
}

std::vector<int64_t> decoded(const fs::path& dir) {
  std::vector<int64_t> out;
  auto files = list_frame_files(dir, ".exr");
  if (files.is_ok())
    for (const auto& f : *files) out.push_back(f.index);
  return out;
}

TEST(FaultDrills, TruncatedGvidGivesTheFramesBeforeTheCut) {
  TempDir dir;
  const Stream s = encode(dir, 4, "--intra-only --qp 4 --preset fast");
  ASSERT_EQ(s.frame_bytes.size(), 4u);
  // Cut in the middle of frame 2's packet: the index, the trailer and frame 3 are gone too.
  const int64_t cut = s.header_bytes + s.frame_bytes[0] + s.frame_bytes[1] + s.frame_bytes[2] / 2;
  ASSERT_TRUE(write_file_atomically(s.path, s.bytes.substr(0, cut)).is_ok());
  auto info = run_gvkit("info " + s.path);
  EXPECT_EQ(info.exit_code, 0) << info.output;
  auto r = run_gvkit("decode " + s.path + " -o " + (dir / "out").string());
  EXPECT_EQ(decoded(dir / "out"), (std::vector<int64_t>{0, 1})) << r.output;
  auto stats = read_json(dir / "out" / "stats.json");
  ASSERT_TRUE(stats.is_ok()) << r.output;
  EXPECT_EQ((*stats)["summary"]["index_rebuilt"], true);
  EXPECT_TRUE(contains(r.output, "index is missing or damaged")) << r.output;
  EXPECT_TRUE(contains(r.output, "2 frames found by a scan")) << r.output;
}

TEST(FaultDrills, BitFlipNamesTheDamagedFrameAndItsDependents) {
  TempDir dir;
  // Intra frames at 0 and 2: damage in frame 0 also loses the P frame 1, not frames 2 and 3.
  const Stream s = encode(dir, 4, "--intra-period 2 --qp 4 --preset fast");
  std::string bad = s.bytes;
  bad[s.header_bytes + s.frame_bytes[0] / 2] ^= 0x10;
  ASSERT_TRUE(write_file_atomically(s.path, bad).is_ok());
  auto r = run_gvkit("decode " + s.path + " -o " + (dir / "out").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "frame 0")) << r.output;
  EXPECT_TRUE(contains(r.output, "2 of 4 frames could not be decoded")) << r.output;
  EXPECT_EQ(decoded(dir / "out"), (std::vector<int64_t>{2, 3})) << r.output;
  auto stats = read_json(dir / "out" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["failed_frames"], 2);
  EXPECT_EQ((*stats)["frames"][2]["status"], "ok");
}

TEST(FaultDrills, SessionCutWhileWrittenReconstructsItsListedFrames) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const fs::path session = dir / "session";
  auto synth =
      run_gvkit("synth -o " + session.string() + " --frames 3 --size 96x72 --no-progress --ict " +
                (data / "ict-facekit").string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  // Cut while frame 2 was written: its images half there, session.json not yet listing it (the
  // writer lists a frame after its images, atomically).
  auto info = read_json(session / "session.json");
  ASSERT_TRUE(info.is_ok());
  (*info)["frames"].erase(size_t{2});
  ASSERT_TRUE(write_json(session / "session.json", *info).is_ok());
  fs::remove(session / "frames" / "frame_000002_k2.png");
  fs::resize_file(session / "frames" / "frame_000002_k1.png", 40);
  auto r = run_gvkit("reconstruct " + session.string() + " -o " + (dir / "scans").string() +
                     " --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(decoded(dir / "scans"), (std::vector<int64_t>{0, 1}));

  // A listed image that was cut: the error names the file; the frames done are kept and the
  // run resumes once the image is back.
  const fs::path image = session / "frames" / "frame_000001_k0.png";
  const std::string good = read_file(image).value();
  fs::remove_all(dir / "scans");
  fs::resize_file(image, 40);
  r = run_gvkit("reconstruct " + session.string() + " -o " + (dir / "scans").string() +
                " --no-progress");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "frame_000001_k0.png")) << r.output;
  ASSERT_TRUE(write_file_atomically(image, good).is_ok());
  r = run_gvkit("reconstruct " + session.string() + " -o " + (dir / "scans").string() +
                " --no-progress --resume");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1 of 2 frames were already done")) << r.output;
  EXPECT_EQ(decoded(dir / "scans"), (std::vector<int64_t>{0, 1}));
  auto stats = read_json(dir / "scans" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["complete"], true);
  EXPECT_EQ((*stats)["summary"]["kept_from_earlier_run"], 1);
  EXPECT_TRUE((*stats)["frames"][0].contains("rms_depth_error_mm"));  // kept with its figures
}

// One out-of-range option per subcommand: exit != 0 and the message names the problem.
TEST(FaultDrills, OutOfRangeOptionsOfEverySubcommand) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string d = dir.path().string();
  ASSERT_TRUE(ensure_directory(dir / "empty").is_ok());
  const std::string session = d + "/session";
  auto synth = run_gvkit("synth -o " + session + " --frames 1 --size 64x48 --no-progress --ict " +
                         (data / "ict-facekit").string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string golden = GVKIT_SOURCE_DIR "/tests/golden/v2/intra_slow_qpm6_64.gvid";
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"info " + d + "/missing.exr", "missing.exr: no such file"},
      {"synth -o " + d + "/s --frames 0", "frames must be"},
      {"synth -o " + d + "/s --size 0x0", "camera size must be"},
      {"reconstruct " + session + " -o " + d + "/o --min-modulation 2", "min_modulation"},
      {"reconstruct " + session + " -o " + d + "/o --unwrap-tolerance -1", "unwrap_tolerance"},
      {"devices --dev-dir", "--dev-dir"},  // its one option is a folder; a missing one lists none
      {"calibrate --synth-board " + d + "/b --poses 99", "--poses must be in 1..12"},
      {"record --source file:" + d + "/missing -o " + d + "/r --buffers 99", "outside [2, 32]"},
      {"facemap clean " + d + "/empty -o " + d + "/o --radius -5", "radius must be >= 0"},
      {"facemap map " + d + "/empty -o " + d + "/o --size 8x8", "--size"},
      {"facemap map " + d + "/empty -o " + d + "/o --method other", "--method"},
      {"facemap compare " + d + "/empty " + d + "/missing", "stats.json: no such file"},
      {"facemap ict-sequence " + d + "/missing -o " + d + "/o --frames -1", "--frames must be"},
      {"facemap make-domain " + d + "/missing -o " + d + "/x.json", "generic_neutral_mesh.obj"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --qp 99", "qp 99 out of range"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --bit-depth 20", "bit depth 20 out of range"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --profile high", "profile 'high' unknown"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --tune merge=maybe",
       "tune merge=maybe: not on or off"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --tune nokey=1", "tune nokey=1: unknown key"},
      {"encode " + d + "/empty -o " + d + "/v.gvid --tune refs=9", "refs 9 out of range"},
      {"decode " + d + "/missing.gvid -o " + d + "/o", "missing.gvid: no such file"},
      {"export " + d + "/missing.gvid -o " + d + "/o --format stl", "--format must be"},
      {"render " + d + "/missing.gvid -o " + d + "/o --msaa 99", "msaa samples must be"},
      {"play " + golden + " --speed -1", "speed must be > 0"},
      {"play " + golden + " --mesh-stride 0", "mesh stride"},
      {"run synthetic -o " + d + "/w --frames -3", "--frames"},
      {"summary " + d + "/w --failures -1", "--failures"},
  };
  for (const Case& c : cases) {
    auto r = run_gvkit(c.args);
    EXPECT_NE(r.exit_code, 0) << "gvkit " << c.args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, c.expect))
        << "gvkit " << c.args << ": the message should name '" << c.expect << "'\n"
        << r.output;
    EXPECT_FALSE(contains(r.output, "internal")) << "gvkit " << c.args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace gvkit
