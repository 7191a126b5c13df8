// Constant-quality rate control (--quality / --tune target-rms-mm): every decoded frame meets the
// target, in fewer bits than the constant QP that meets it on its worst frame; the options and
// unreachable targets are rejected with messages that name the option.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/quality_controller.hpp"

namespace gvkit::codec {
namespace {

struct Decoded {
  std::vector<GeometryError> errors;  // per frame, decoder output against the input
  int64_t bits = 0;                   // all frame packets
};

Decoded encode_and_decode(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                          const EncoderOptions& options) {
  Decoded out;
  auto bytes = encode_gvid(frames, info, options);
  EXPECT_TRUE(bytes.is_ok()) << bytes.status().message();
  if (!bytes.is_ok()) return out;
  auto reader = GvidReader::open_memory(*bytes, "cq.gvid");
  EXPECT_TRUE(reader.is_ok()) << reader.status().message();
  if (!reader.is_ok()) return out;
  for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
    auto decoded = (*reader)->decode_frame(f);
    EXPECT_TRUE(decoded.is_ok()) << decoded.status().message();
    if (!decoded.is_ok()) return out;
    out.errors.push_back(geometry_error(frames[f], *decoded));
    out.bits += (*reader)->frame_bits(f);
  }
  return out;
}

double worst_psnr(const Decoded& d, double peak) {
  double worst = INFINITY;
  for (const GeometryError& e : d.errors) worst = std::min(worst, e.psnr_db(peak));
  return worst;
}

class ConstantQuality : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::GeometryVideoOptions vo;
    vo.size = 64;
    vo.frames = 8;
    frames_ = testing::make_analytic_video(vo);
    auto info = make_sequence_info(frames_, 16, vo.fps);
    ASSERT_TRUE(info.is_ok()) << info.status().message();
    info_ = *info;
    base_.preset = Preset::kFast;
    base_.intra_period = 4;  // I P P P I P P P
  }
  std::vector<GeometryImage> frames_;
  SequenceInfo info_;
  EncoderOptions base_;
};

TEST_F(ConstantQuality, EveryFrameMeetsTheTargetPsnrInFewerBitsThanConstantQp) {
  const double peak = info_.box_diagonal_mm();
  for (const double target : {62.0, 74.0}) {
    EncoderOptions cq = base_;
    cq.target_psnr_db = target;
    cq.qp = 20;  // a start far from the answer: the first frame searches finer
    const Decoded q = encode_and_decode(frames_, info_, cq);
    ASSERT_EQ(q.errors.size(), frames_.size());
    for (size_t f = 0; f < q.errors.size(); ++f)
      EXPECT_GE(q.errors[f].psnr_db(peak), target) << "target " << target << " dB, frame " << f;

    // Constant QP (the same QP in I and P frames) at the coarsest QP whose worst frame meets the
    // target.
    int qp_star = -48;
    int64_t bits_star = 0;
    for (int qp = 30; qp >= -48; --qp) {
      EncoderOptions cqp = base_;
      cqp.qp = qp;
      cqp.p_qp_offset = 0;
      const Decoded c = encode_and_decode(frames_, info_, cqp);
      if (worst_psnr(c, peak) >= target) {
        qp_star = qp;
        bits_star = c.bits;
        break;
      }
    }
    ASSERT_GT(bits_star, 0) << "no constant QP meets " << target << " dB";
    EXPECT_LT(q.bits, bits_star) << "target " << target << " dB, constant QP " << qp_star;
  }
}

TEST_F(ConstantQuality, AnIntraTargetOffsetRaisesTheIFramesOnly) {
  const double peak = info_.box_diagonal_mm();
  EncoderOptions cq = base_;
  cq.target_psnr_db = 66;
  cq.intra_target_offset_db = 4;
  const Decoded q = encode_and_decode(frames_, info_, cq);
  ASSERT_EQ(q.errors.size(), frames_.size());
  for (size_t f = 0; f < q.errors.size(); ++f) {
    const bool intra = cq.is_intra(static_cast<int64_t>(f));
    EXPECT_GE(q.errors[f].psnr_db(peak), intra ? 70.0 : 66.0) << "frame " << f;
  }
}

TEST_F(ConstantQuality, TargetRmsHoldsOnEveryFrameAndTheQpIsTheCoarsestWithinTheBracket) {
  EncoderOptions cq = base_;
  cq.target_rms_mm = 0.05;
  auto controller = QualityController::create(cq, info_);
  ASSERT_TRUE(controller.is_ok()) << controller.status().message();
  std::vector<SamplePlane> reference;
  for (size_t i = 0; i < frames_.size(); ++i) {
    int qp = 99;
    auto encoded = encode_sequence_frame(frames_[i], info_, cq, static_cast<uint32_t>(i), reference,
                                         nullptr, &qp, nullptr, controller->get());
    ASSERT_TRUE(encoded.is_ok()) << encoded.status().message();
    EXPECT_LE(geometry_error(frames_[i], encoded->reconstruction).rms_mm, 0.05) << "frame " << i;
    // One QP coarser misses the target (unless the bracket stopped the climb at +2).
    EncoderOptions coarser = cq;
    coarser.target_rms_mm = 0;
    coarser.qp = qp + 1;
    coarser.p_qp_offset = 0;
    const bool intra = cq.is_intra(static_cast<int64_t>(i));
    auto next = encode_frame(frames_[i], info_, coarser, static_cast<uint32_t>(i),
                             intra ? nullptr : &reference);
    ASSERT_TRUE(next.is_ok());
    const int encodes = (*controller)->frame_encodes()[i];
    if (encodes < 1 + QualityController::kMaxCoarser || i == 0) {
      EXPECT_GT(geometry_error(frames_[i], next->reconstruction).rms_mm, 0.05)
          << "frame " << i << " at QP " << qp << " is not the coarsest";
    }
    EXPECT_GE(encodes, 1);
    EXPECT_LE(encodes, 14);
    reference = encoded->planes;
  }
  EXPECT_EQ((*controller)->frames_missed(), 0);
}

TEST_F(ConstantQuality, BadOptionsAndUnreachableTargetsFailNamingTheOption) {
  EncoderOptions o = base_;
  o.target_psnr_db = -1;
  EXPECT_NE(o.check().message().find("target PSNR"), std::string::npos) << o.check().message();
  o.target_psnr_db = 70;
  o.target_rms_mm = 0.1;
  EXPECT_NE(o.check().message().find("exclude each other"), std::string::npos);
  o.target_rms_mm = 0;
  o.bitrate_kbps = 500;
  EXPECT_NE(o.check().message().find("target PSNR: constant quality and a bitrate"),
            std::string::npos)
      << o.check().message();
  o.bitrate_kbps = 0;
  o.lossless = true;
  EXPECT_NE(o.check().message().find("constant quality needs lossy coding"), std::string::npos);
  o.lossless = false;
  o.max_error_mm = 0.1;
  EXPECT_FALSE(o.check().is_ok());
  o.max_error_mm = 0;
  EXPECT_TRUE(o.check().is_ok()) << o.check().message();

  // 150 dB asks for an RMS error far below one 16-bit quantization step of this box.
  o.target_psnr_db = 150;
  auto too_fine = QualityController::create(o, info_);
  ASSERT_FALSE(too_fine.is_ok());
  EXPECT_NE(too_fine.status().message().find("target PSNR 150"), std::string::npos)
      << too_fine.status().message();
  auto stream = encode_gvid(frames_, info_, o);
  EXPECT_FALSE(stream.is_ok());
}

}  // namespace
}  // namespace gvkit::codec
