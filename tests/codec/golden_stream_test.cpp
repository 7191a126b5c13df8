// Golden streams in tests/golden/ must keep decoding to exactly the same samples: each stream's
// decoded frames are compared by CRC-32 of their xyz floats with tests/golden/golden.json.
// GVKIT_UPDATE_GOLDEN=1 writes the streams that are missing and adds their CRCs (a new case after
// a deliberate format change, with a version bump); existing streams are kept, since they pin the
// decoding of the older versions.
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::codec {
namespace {
namespace fs = std::filesystem;

const fs::path kGoldenDir = GVKIT_GOLDEN_DIR;

struct GoldenCase {
  const char* file;
  int size;
  int frames;
  EncoderOptions options;
  double shift_px = 0;  // the picture moves by (shift_px, shift_px / 2) per frame
};

std::vector<GoldenCase> cases() {
  EncoderOptions lossless, fast, slow_no_gv, eight_bit, inter, lossless_inter, near_affine,
      plane_qp, qpel_td, hpel_lossless, shared_fast, shared_lossless, bframes_fast,
      bframes_lossless, refs_fast, refs_lossless, tx16_fast, tx8_slow, cross_fast, cross_near,
      ctx_fast, ctx_lossless;
  EncoderOptions part_slow, deblock_fast, temporal_slow;
  temporal_slow.qp = 6;  // version 1.9: temporal contexts on every 1.8 default, slow, I P B
  temporal_slow.preset = Preset::kSlow;
  temporal_slow.bframes = 1;
  deblock_fast.qp = 12;  // version 1.8: the deblocking filter on every 1.7 default, fast, I P B
  deblock_fast.preset = Preset::kFast;
  deblock_fast.bframes = 1;
  part_slow.qp = 0;  // version 1.7: inter partitions, slow preset, P frames with the 1.6 tools
  part_slow.preset = Preset::kSlow;
  part_slow.bframes = 0;
  part_slow.shared_motion = true;
  part_slow.partitions = true;
  part_slow.cross_plane_contexts = false;  // (the stream was written before that 1.7 tool)
  refs_fast.qp = 0;  // version 1.6: three reference frames, fast preset, P frames only
  refs_fast.preset = Preset::kFast;
  refs_fast.bframes = 0;
  refs_fast.refs = 3;
  refs_fast.max_transform = 4;
  refs_lossless.lossless = true;  // version 1.6: two references with B frames, shared motion
  refs_lossless.preset = Preset::kSlow;
  refs_lossless.bframes = 1;
  refs_lossless.refs = 2;
  refs_lossless.shared_motion = true;
  tx16_fast.qp = 0;  // version 1.6: larger transforms up to 16x16, fast preset, I, P and B
  tx16_fast.preset = Preset::kFast;
  tx16_fast.bframes = 1;
  tx16_fast.max_transform = 16;
  tx16_fast.refs = 1;
  tx8_slow.qp = -6;  // version 1.6: larger transforms up to 8x8, slow preset, I and P
  tx8_slow.preset = Preset::kSlow;
  tx8_slow.bframes = 0;
  tx8_slow.intra_period = 3;
  tx8_slow.max_transform = 8;
  tx8_slow.refs = 1;
  // The streams before 1.6 and those of the other 1.6 tools were written without cross-plane
  // prediction.
  for (EncoderOptions* o :
       {&lossless, &fast, &slow_no_gv, &eight_bit, &inter, &lossless_inter, &near_affine, &plane_qp,
        &qpel_td, &hpel_lossless, &shared_fast, &shared_lossless, &bframes_fast, &bframes_lossless,
        &refs_fast, &refs_lossless, &tx16_fast, &tx8_slow})
    o->cross_plane = false;
  cross_fast.qp = 0;  // version 1.6: cross-plane prediction, one B frame, fast preset
  cross_fast.preset = Preset::kFast;
  cross_fast.bframes = 1;
  cross_near.max_error_mm = 0.05;  // version 1.6: cross-plane prediction, near-lossless, slow
  cross_near.preset = Preset::kSlow;
  // ... without the other 1.6 tools.
  for (EncoderOptions* o : {&cross_fast, &cross_near}) {
    o->refs = 1;
    o->max_transform = 4;
  }
  // The streams before 1.7 were written without either 1.7 tool (the cross-plane contexts
  // streams without inter partitions, below; the partitions stream without the contexts).
  for (EncoderOptions* o : {&lossless,     &fast,
                            &slow_no_gv,   &eight_bit,
                            &inter,        &lossless_inter,
                            &near_affine,  &plane_qp,
                            &qpel_td,      &hpel_lossless,
                            &shared_fast,  &shared_lossless,
                            &bframes_fast, &bframes_lossless,
                            &refs_fast,    &refs_lossless,
                            &tx16_fast,    &tx8_slow,
                            &cross_fast,   &cross_near}) {
    o->cross_plane_contexts = false;
    o->partitions = false;
    testing::format_tools_before(8, o);  // a 1.7 stream
    o->intra_rdo = false;                // (nor the fast preset's RDO in I frames)
  }
  for (EncoderOptions* o : {&ctx_fast, &ctx_lossless}) o->partitions = false;
  // The streams before 1.8 were written without the deblocking filter (the ones above too).
  for (EncoderOptions* o : {&ctx_fast, &ctx_lossless, &part_slow}) o->deblocking = false;
  // The fast preset's I frames were decided by SATD costs in every stream here.
  ctx_fast.intra_rdo = deblock_fast.intra_rdo = false;
  // ... and those before 1.9 without temporal contexts.
  for (EncoderOptions* o : {&ctx_fast, &ctx_lossless, &part_slow, &deblock_fast}) {
    testing::format_tools_before(9, o);  // a 1.8 stream
  }
  ctx_fast.qp = 0;  // version 1.7: cross-plane contexts on the 1.6 defaults, one B frame, fast
  ctx_fast.preset = Preset::kFast;
  ctx_fast.bframes = 1;
  ctx_lossless.lossless = true;  // version 1.7: cross-plane contexts, lossless, slow, P frames
  ctx_lossless.preset = Preset::kSlow;
  ctx_lossless.bframes = 0;
  bframes_fast.qp = 0;  // version 1.5: one B frame between anchors, fast preset
  bframes_fast.preset = Preset::kFast;
  bframes_fast.bframes = 1;
  bframes_lossless.lossless = true;  // version 1.5: two B frames, the last frame a trailing P
  bframes_lossless.preset = Preset::kSlow;
  bframes_lossless.bframes = 2;
  shared_fast.qp = 0;  // version 1.4: shared motion, inter decimation, fast preset
  shared_fast.preset = Preset::kFast;
  shared_fast.intra_period = 3;
  shared_fast.shared_motion = true;
  shared_lossless.lossless = true;  // version 1.4: shared motion with the joint search, lossless
  shared_lossless.preset = Preset::kFast;
  shared_lossless.shared_motion = true;
  qpel_td.qp = 0;  // version 1.3: quarter-sample motion (with TD prediction), slow preset
  qpel_td.intra_period = 3;
  hpel_lossless.lossless = true;  // version 1.3: half-sample motion refinement, lossless
  hpel_lossless.preset = Preset::kFast;
  hpel_lossless.subpel = 2;
  near_affine.max_error_mm = 0.05;  // version 1.2: near-lossless, affine value prediction
  near_affine.preset = Preset::kFast;
  near_affine.value_prediction = ValuePrediction::kAffine;
  plane_qp.qp = 0;  // version 1.2: plane QP offsets, weighted value prediction
  plane_qp.preset = Preset::kFast;
  plane_qp.plane_qp_offset[0] = -2;
  plane_qp.plane_qp_offset[2] = 3;
  plane_qp.value_prediction = ValuePrediction::kWeighted;
  lossless_inter.lossless = true;  // version 1.1: adaptive level coding, with P frames
  lossless_inter.preset = Preset::kFast;
  for (EncoderOptions* o : {&lossless, &fast, &slow_no_gv, &eight_bit}) o->intra_only = true;
  inter.qp = 0;
  inter.preset = Preset::kFast;
  inter.intra_period = 3;
  lossless.lossless = true;
  lossless.preset = Preset::kFast;
  fast.qp = 6;
  fast.preset = Preset::kFast;
  slow_no_gv.qp = -12;
  slow_no_gv.geometry_modes = false;
  eight_bit.bit_depth = 8;
  eight_bit.qp = 20;
  return {{"analytic_lossless_48.gvid", 48, 2, lossless},
          {"analytic_qp6_fast_64.gvid", 64, 2, fast},
          {"analytic_qpm12_slow_nogv_64.gvid", 64, 2, slow_no_gv},
          {"analytic_8bit_qp20_64.gvid", 64, 3, eight_bit},
          {"analytic_ippi_qp0_fast_64.gvid", 64, 4, inter},
          {"analytic_lossless_ipp_v1_1_48.gvid", 48, 3, lossless_inter},
          {"analytic_near_affine_ipp_v1_2_48.gvid", 48, 3, near_affine},
          {"analytic_planeqp_weighted_ipp_v1_2_48.gvid", 48, 3, plane_qp},
          {"analytic_qpel_td_ippi_v1_3_48.gvid", 48, 4, qpel_td, 0.75},
          {"analytic_hpel_lossless_ipp_v1_3_48.gvid", 48, 3, hpel_lossless, 0.5},
          {"analytic_shared_qp0_ippi_v1_4_48.gvid", 48, 4, shared_fast, 0.75},
          {"analytic_shared_lossless_ipp_v1_4_48.gvid", 48, 3, shared_lossless, 0.5},
          {"analytic_bframes_qp0_ibpbp_v1_5_48.gvid", 48, 5, bframes_fast, 0.75},
          {"analytic_bframes_lossless_ibbpp_v1_5_48.gvid", 48, 5, bframes_lossless, 0.5},
          {"analytic_refs3_qp0_ipppp_v1_6_48.gvid", 48, 5, refs_fast, 0.75},
          {"analytic_refs2_lossless_ibpbpbp_v1_6_48.gvid", 48, 7, refs_lossless, 0.5},
          {"analytic_tx16_qp0_ibpbp_v1_6_48.gvid", 48, 5, tx16_fast, 0.75},
          {"analytic_tx8_slow_qpm6_ippi_v1_6_48.gvid", 48, 4, tx8_slow, 0.75},
          {"analytic_xplane_qp0_ibpbp_v1_6_48.gvid", 48, 5, cross_fast, 0.75},
          {"analytic_xplane_near_ipp_v1_6_48.gvid", 48, 3, cross_near, 0.5},
          {"analytic_xctx_qp0_ibpbp_v1_7_48.gvid", 48, 5, ctx_fast, 0.75},
          {"analytic_xctx_lossless_ipp_v1_7_48.gvid", 48, 3, ctx_lossless, 0.5},
          {"analytic_part_slow_qp0_ipppp_v1_7_48.gvid", 48, 5, part_slow, 0.75},
          {"analytic_deblock_qp12_ibpbp_v1_8_48.gvid", 48, 5, deblock_fast, 0.75},
          {"analytic_temporal_slow_qp6_ibpbp_v1_9_48.gvid", 48, 5, temporal_slow, 0.75}};
}

uint32_t frame_crc(const GeometryImage& image) {
  uint32_t crc = 0;
  for (int y = 0; y < image.xyz_mm.rows; ++y)
    crc = crc32(image.xyz_mm.ptr(y), image.xyz_mm.cols * image.xyz_mm.elemSize(), crc);
  return crc;
}

TEST(GoldenStreams, DecodeToTheRecordedSamples) {
  const char* update = std::getenv("GVKIT_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") {
    auto existing = read_json(kGoldenDir / "golden.json");
    ASSERT_TRUE(existing.is_ok()) << existing.status().message();
    nlohmann::json record = *existing;
    for (const GoldenCase& c : cases()) {
      if (fs::exists(kGoldenDir / c.file)) continue;
      testing::GeometryVideoOptions o;
      o.size = c.size;
      o.frames = c.frames;
      auto frames = testing::make_analytic_video(o);
      if (c.shift_px != 0) testing::move_in_picture(&frames, c.shift_px);
      auto info = make_sequence_info(frames, c.options.bit_depth, 30.0);
      ASSERT_TRUE(info.is_ok());
      auto bytes = encode_gvid(frames, *info, c.options);
      ASSERT_TRUE(bytes.is_ok());
      ASSERT_TRUE(write_file_atomically(kGoldenDir / c.file, *bytes).is_ok());
      auto reader = GvidReader::open_memory(*bytes, c.file);
      ASSERT_TRUE(reader.is_ok());
      for (int64_t f = 0; f < (*reader)->frame_count(); ++f)
        record[c.file].push_back(frame_crc((*reader)->decode_frame(f).value()));
    }
    ASSERT_TRUE(write_json(kGoldenDir / "golden.json", record).is_ok());
  }
  auto record = read_json(kGoldenDir / "golden.json");
  ASSERT_TRUE(record.is_ok()) << record.status().message();
  for (const GoldenCase& c : cases()) {
    auto reader = GvidReader::open(kGoldenDir / c.file);
    ASSERT_TRUE(reader.is_ok()) << reader.status().message();
    ASSERT_EQ((*reader)->frame_count(), c.frames);
    EXPECT_FALSE((*reader)->index_rebuilt());
    for (int64_t f = 0; f < c.frames; ++f) {
      auto frame = (*reader)->decode_frame(f);
      ASSERT_TRUE(frame.is_ok()) << frame.status().message();
      EXPECT_EQ(frame_crc(*frame), (*record)[c.file][f].get<uint32_t>())
          << c.file << " frame " << f;
    }
  }
}

}  // namespace
}  // namespace gvkit::codec
