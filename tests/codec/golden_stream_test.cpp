// Golden streams (tests/golden/) must keep decoding to exactly the same samples: each stream's
// decoded frames are compared by CRC-32 of their xyz floats (and texture) with its folder's
// golden.json.
// - v2/: format 2.0 streams, a few small ones per profile, written by the encoder from the cases
//   below; the encoder must still write them byte for byte. An encoder change that keeps the
//   format (faster search, better decisions) changes those bytes: regenerate the v2 streams and
//   their CRCs with
//       GVKIT_UPDATE_GOLDEN=1 build/tests/codec/golden_stream_test
//   and commit them. A decoder change must never change the CRCs of an existing stream.
// - v1/: legacy 1.x streams, decode only (the reader still reads 1.x; nothing writes it).
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::codec {
namespace {
namespace fs = std::filesystem;

const fs::path kGoldenDir = GVKIT_GOLDEN_DIR;
const fs::path kV1 = kGoldenDir / "v1", kV2 = kGoldenDir / "v2";

struct GoldenCase {
  const char* file;
  int size;
  int frames;
  EncoderOptions options;
  double shift_px = 0;   // the picture moves by (shift_px, shift_px / 2) per frame
  bool texture = false;  // with a texture plane
};

// The format 2.0 streams: per profile, the tools its frames can use, at sizes that keep each
// stream a few kilobytes.
std::vector<GoldenCase> v2_cases() {
  EncoderOptions main_fast, main_slow, main_half, intra_slow, intra_8bit, lossless_slow,
      lossless_near;
  main_fast.preset = Preset::kFast;  // I B P B P, texture, default tools
  main_fast.qp = 6;
  main_fast.intra_period = 5;
  main_slow.preset = Preset::kSlow;  // I P P P P: 3 references, partitions, merge, TD16
  main_slow.qp = 0;
  main_slow.bframes = 0;
  main_slow.shared_motion = true;
  main_slow.value_prediction = ValuePrediction::kAffine;
  main_half.preset = Preset::kFast;  // half resolution in every frame, plane QP offsets
  main_half.qp = 18;
  main_half.resolution = Resolution::kHalf;
  main_half.plane_qp_offset[2] = 2;
  intra_slow.preset = Preset::kSlow;  // large transforms, quadratic intra, deblocking
  intra_slow.qp = -6;
  intra_slow.profile = Profile::kIntra;
  intra_8bit.preset = Preset::kFast;  // 8-bit samples, no geometry modes
  intra_8bit.bit_depth = 8;
  intra_8bit.qp = 20;
  intra_8bit.intra_only = true;
  intra_8bit.geometry_modes = false;
  lossless_slow.preset = Preset::kSlow;  // I B P B P lossless
  lossless_slow.lossless = true;
  lossless_slow.bframes = 1;
  lossless_near.preset = Preset::kFast;  // near-lossless P frames, shared motion
  lossless_near.max_error_mm = 0.05;
  lossless_near.shared_motion = true;
  return {{"main_fast_qp6_ibpbp_texture_48.gvid", 48, 5, main_fast, 0.75, true},
          {"main_slow_qp0_ipppp_48.gvid", 48, 5, main_slow, 0.75},
          {"main_half_qp18_ibpbp_64.gvid", 64, 5, main_half, 0.75},
          {"intra_slow_qpm6_64.gvid", 64, 2, intra_slow},
          {"intra_8bit_qp20_48.gvid", 48, 2, intra_8bit},
          {"lossless_slow_ibpbp_48.gvid", 48, 5, lossless_slow, 0.5},
          {"lossless_near_ipp_48.gvid", 48, 3, lossless_near, 0.5}};
}

std::vector<GeometryImage> case_frames(const GoldenCase& c) {
  testing::GeometryVideoOptions o;
  o.size = c.size;
  o.frames = c.frames;
  auto frames = testing::make_analytic_video(o);
  if (c.shift_px != 0) testing::move_in_picture(&frames, c.shift_px);
  if (c.texture)
    for (size_t f = 0; f < frames.size(); ++f) {
      cv::Mat t(c.size, c.size, CV_32F);
      for (int y = 0; y < c.size; ++y)
        for (int x = 0; x < c.size; ++x)
          t.at<float>(y, x) =
              static_cast<float>(((x + 2 * y + 3 * static_cast<int>(f)) % 64) / 63.0);
      frames[f].texture = t;
    }
  return frames;
}

Result<std::string> encode_case(const GoldenCase& c) {
  const auto frames = case_frames(c);
  GVKIT_ASSIGN_OR_RETURN(const SequenceInfo info,
                         make_sequence_info(frames, c.options.bit_depth, 30.0));
  return encode_gvid(frames, info, c.options);
}

uint32_t frame_crc(const GeometryImage& image) {
  uint32_t crc = 0;
  for (int y = 0; y < image.xyz_mm.rows; ++y)
    crc = crc32(image.xyz_mm.ptr(y), image.xyz_mm.cols * image.xyz_mm.elemSize(), crc);
  for (int y = 0; y < image.texture.rows; ++y)
    crc = crc32(image.texture.ptr(y), image.texture.cols * image.texture.elemSize(), crc);
  return crc;
}

bool updating() {
  const char* update = std::getenv("GVKIT_UPDATE_GOLDEN");
  return update && std::string(update) == "1";
}

// Every file of `record` (name -> frame CRCs) in `dir` decodes to its CRCs.
void expect_recorded_samples(const fs::path& dir, const nlohmann::json& record) {
  ASSERT_FALSE(record.empty()) << dir;
  for (const auto& [file, crcs] : record.items()) {
    SCOPED_TRACE(file);
    auto reader = GvidReader::open(dir / file);
    ASSERT_TRUE(reader.is_ok()) << reader.status().message();
    ASSERT_EQ((*reader)->frame_count(), static_cast<int64_t>(crcs.size()));
    EXPECT_FALSE((*reader)->index_rebuilt());
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
      auto frame = (*reader)->decode_frame(f);
      ASSERT_TRUE(frame.is_ok()) << frame.status().message();
      EXPECT_EQ(frame_crc(*frame), crcs[f].get<uint32_t>()) << "frame " << f;
    }
  }
}

nlohmann::json crcs_of(const std::string& bytes, const std::string& name) {
  nlohmann::json crcs = nlohmann::json::array();
  auto reader = GvidReader::open_memory(bytes, name).value();
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    crcs.push_back(frame_crc(reader->decode_frame(f).value()));
  return crcs;
}

TEST(GoldenStreams, V2DecodeToTheRecordedSamples) {
  if (updating()) {
    nlohmann::json record = nlohmann::json::object();
    ASSERT_TRUE(ensure_directory(kV2).is_ok());
    for (const GoldenCase& c : v2_cases()) {
      auto bytes = encode_case(c);
      ASSERT_TRUE(bytes.is_ok()) << c.file << ": " << bytes.status().message();
      ASSERT_TRUE(write_file_atomically(kV2 / c.file, *bytes).is_ok());
      record[c.file] = crcs_of(*bytes, c.file);
    }
    ASSERT_TRUE(write_json(kV2 / "golden.json", record).is_ok());
  }
  auto record = read_json(kV2 / "golden.json");
  ASSERT_TRUE(record.is_ok()) << record.status().message();
  ASSERT_EQ(record->size(), v2_cases().size());
  expect_recorded_samples(kV2, *record);
  // One stream per profile at least, each with the profile its case names.
  for (const GoldenCase& c : v2_cases()) {
    auto reader = GvidReader::open(kV2 / c.file).value();
    EXPECT_EQ(reader->format().major, 2);
    EXPECT_EQ(std::string(c.file).rfind(profile_name(reader->format().profile), 0), 0u) << c.file;
  }
}

TEST(GoldenStreams, EncoderWritesTheV2StreamsByteForByte) {
  for (const GoldenCase& c : v2_cases()) {
    auto bytes = encode_case(c);
    ASSERT_TRUE(bytes.is_ok()) << c.file << ": " << bytes.status().message();
    auto golden = read_file(kV2 / c.file);
    ASSERT_TRUE(golden.is_ok()) << golden.status().message();
    EXPECT_TRUE(*bytes == *golden)
        << "tests/golden/v2/" << c.file << ": the encoder now writes " << bytes->size()
        << " bytes, the golden stream has " << golden->size()
        << ". If the encoder changed on purpose (the format did not), regenerate the v2 streams "
           "and their CRCs with GVKIT_UPDATE_GOLDEN=1 build/tests/codec/golden_stream_test and "
           "commit them.";
  }
}

TEST(GoldenStreams, LegacyV1DecodeToTheRecordedSamples) {
  auto record = read_json(kV1 / "golden.json");
  ASSERT_TRUE(record.is_ok()) << record.status().message();
  if (updating()) {  // records legacy streams that have no CRCs yet; never rewrites a stream
    for (const auto& entry : fs::directory_iterator(kV1)) {
      const std::string name = entry.path().filename().string();
      if (entry.path().extension() != ".gvid" || record->contains(name)) continue;
      (*record)[name] = crcs_of(read_file(entry.path()).value(), name);
    }
    ASSERT_TRUE(write_json(kV1 / "golden.json", *record).is_ok());
  }
  expect_recorded_samples(kV1, *record);
  for (const auto& [file, crcs] : record->items())
    EXPECT_TRUE(GvidReader::open(kV1 / file).value()->format().legacy()) << file;
}

}  // namespace
}  // namespace gvkit::codec
