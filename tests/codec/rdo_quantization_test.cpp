// Rate-distortion optimised quantization (codec/src/rdo_quantization.hpp): what it returns for
// lambda 0 and a huge lambda, the levels it may choose, that it lowers the real SSD + lambda x
// CABAC bits of coded blocks against the fixed-offset quantizers, and that its choice of the last
// position equals the plain form's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/cabac_encoder.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "macroblock_syntax.hpp"
#include "rdo_quantization.hpp"

namespace gvkit::codec::detail {
namespace {

// A residual block: a smooth ramp plus Laplacian-ish noise of `noise` samples (|value| < 2^16).
std::vector<int32_t> residual_block(int n, double noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::exponential_distribution<double> e(1.0 / noise);
  const double gx = 40 * u(rng), gy = 40 * u(rng), dc = 200 * u(rng);
  std::vector<int32_t> r(static_cast<size_t>(n * n));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double v =
          dc + gx * (x - n / 2.0) + gy * (y - n / 2.0) + (u(rng) < 0 ? -1 : 1) * e(rng);
      r[static_cast<size_t>(y * n + x)] = static_cast<int32_t>(std::lround(v));
    }
  return r;
}

// Squared error of the levels' reconstruction against the residual.
double reconstruction_ssd(int n, const int32_t* levels, int qp, const int32_t* residual) {
  int64_t dq[256];
  int32_t rec[256];
  if (n == 16) {
    dequantize16x16(levels, qp, dq);
    inverse_transform16x16(dq, rec);
  } else {
    dequantize(n, levels, qp, dq);
    if (n == 4)
      inverse_transform4x4(dq, rec);
    else
      inverse_transform8x8(dq, rec);
  }
  double ssd = 0;
  for (int i = 0; i < n * n; ++i) {
    const double d = static_cast<double>(residual[i]) - rec[i];
    ssd += d * d;
  }
  return ssd;
}

enum class Quantizer { kIntra, kInter, kRdo };

// SSD + lambda x bits over `blocks` blocks coded one after the other on one context set (the
// contexts adapt as in a plane), each block's levels from `quantizer`.
double total_cost(int n, int qp, double lambda, Quantizer quantizer, int blocks, double noise,
                  unsigned seed) {
  std::mt19937 rng(seed);
  ContextSet ctx{};
  double cost = 0;
  for (int b = 0; b < blocks; ++b) {
    const std::vector<int32_t> r = residual_block(n, noise, rng);
    int32_t coeffs[256], levels[256];
    forward_transform(n, r.data(), coeffs);
    if (quantizer == Quantizer::kRdo)
      quantize_rdo(n, coeffs, qp, lambda, ctx, levels);
    else if (n == 16)
      quantize16x16(coeffs, qp, quantizer == Quantizer::kInter, levels);
    else if (quantizer == Quantizer::kInter)
      quantize_inter(n, coeffs, qp, levels);
    else
      quantize(n, coeffs, qp, levels);
    CabacBitCounter counter;
    counter.encode(ctx.cbf[0], any_nonzero(levels, n * n));
    if (any_nonzero(levels, n * n)) write_residual(counter, ctx, levels, n);
    cost += reconstruction_ssd(n, levels, qp, r.data()) + lambda * counter.bits();
  }
  return cost;
}

double lambda_of(int qp_prime) { return 0.85 * std::pow(2.0, (qp_prime - 12) / 3.0); }

// The one-pass choice of the last significant position against the plain two-pass one, on
// random costs: small whole numbers (many equal totals, also equal to the all-zero cost), and
// fractions whose sums round.
TEST(RdoQuantization, LastPositionEqualsThePlainChoice) {
  std::mt19937 rng(7);
  int none = 0, some = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 256);
    const bool whole = trial % 2 == 0;
    const auto cost = [&] {
      return whole ? static_cast<double>(rng() % 6)
                   : std::ldexp(static_cast<double>(rng() % 100000), -10);
    };
    std::vector<int32_t> chosen(n);
    std::vector<double> chosen_cost(n), last_extra(n), after(n);
    double all_zero = 0;
    for (int j = n - 1; j >= 0; --j) {
      chosen[j] = rng() % 3 == 0 ? 0 : 1 + static_cast<int32_t>(rng() % 3);
      chosen_cost[j] = cost();
      last_extra[j] = cost();
      after[j] = all_zero;
      all_zero += cost();
    }
    if (trial % 5 == 0) all_zero = cost();
    const int fast = last_significant_position(n, chosen.data(), chosen_cost.data(),
                                               last_extra.data(), after.data(), all_zero);
    const int plain = last_significant_position_reference(
        n, chosen.data(), chosen_cost.data(), last_extra.data(), after.data(), all_zero);
    ASSERT_EQ(fast, plain) << "trial " << trial << ", n " << n;
    (fast < 0 ? none : some) += 1;
  }
  EXPECT_GT(none, 1000);
  EXPECT_GT(some, 1000);
}

TEST(RdoQuantization, LambdaZeroRoundsToTheNearestLevel) {
  std::mt19937 rng(7);
  for (const int n : {4, 8, 16})
    for (const int qp : {20, 48, 70}) {
      for (int t = 0; t < 20; ++t) {
        const std::vector<int32_t> r = residual_block(n, 300, rng);
        int32_t coeffs[256], levels[256];
        int64_t numer[256];
        forward_transform(n, r.data(), coeffs);
        quantize_rdo(n, coeffs, qp, 0.0, ContextSet{}, levels);
        const int qbits = n == 16 ? quantization_numerators16x16(coeffs, qp, numer)
                                  : quantization_numerators(n, coeffs, qp, numer);
        for (int k = 0; k < n * n; ++k) {
          const int32_t nearest =
              static_cast<int32_t>((numer[k] + (int64_t{1} << (qbits - 1))) >> qbits);
          EXPECT_EQ(levels[k], coeffs[k] < 0 ? -nearest : nearest) << "n " << n << " qp " << qp;
        }
      }
    }
}

TEST(RdoQuantization, LevelsStayBetweenZeroAndTheNearestWithTheCoefficientsSign) {
  std::mt19937 rng(11);
  ContextSet ctx{};
  for (const int n : {4, 8, 16})
    for (const int qp : {30, 60}) {
      int nonzero = 0;
      for (int t = 0; t < 30; ++t) {
        const std::vector<int32_t> r = residual_block(n, 200, rng);
        int32_t coeffs[256], levels[256], nearest[256];
        int64_t numer[256];
        forward_transform(n, r.data(), coeffs);
        quantize_rdo(n, coeffs, qp, lambda_of(qp), ctx, levels);
        const int qbits = n == 16 ? quantization_numerators16x16(coeffs, qp, numer)
                                  : quantization_numerators(n, coeffs, qp, numer);
        for (int k = 0; k < n * n; ++k) {
          nearest[k] = static_cast<int32_t>((numer[k] + (int64_t{1} << (qbits - 1))) >> qbits);
          ASSERT_LE(std::abs(levels[k]), nearest[k]);
          if (levels[k]) {
            ASSERT_EQ(levels[k] < 0, coeffs[k] < 0);
            ++nonzero;
          }
        }
      }
      EXPECT_GT(nonzero, 0) << "n " << n << " qp " << qp;
    }
}

TEST(RdoQuantization, AHugeLambdaCodesNothing) {
  std::mt19937 rng(3);
  for (const int n : {4, 8, 16}) {
    const std::vector<int32_t> r = residual_block(n, 50, rng);
    int32_t coeffs[256], levels[256];
    forward_transform(n, r.data(), coeffs);
    quantize_rdo(n, coeffs, 40, 1e30, ContextSet{}, levels);
    EXPECT_FALSE(any_nonzero(levels, n * n)) << "n " << n;
  }
}

// The real cost (SSD of the reconstruction + lambda x the bits write_residual codes, contexts
// adapting over the blocks) with RDO quantization is below both fixed-offset quantizers'.
TEST(RdoQuantization, LowersTheRateDistortionCostOfCodedBlocks) {
  for (const int n : {4, 8, 16})
    for (const int qp : {36, 60}) {
      const double lambda = lambda_of(qp), noise = 2.0 * quantizer_step(qp);
      const int blocks = n == 16 ? 60 : 200;
      const double intra = total_cost(n, qp, lambda, Quantizer::kIntra, blocks, noise, 5);
      const double inter = total_cost(n, qp, lambda, Quantizer::kInter, blocks, noise, 5);
      const double rdo = total_cost(n, qp, lambda, Quantizer::kRdo, blocks, noise, 5);
      EXPECT_LT(rdo, 0.99 * intra) << "n " << n << " qp " << qp;
      EXPECT_LT(rdo, 0.99 * inter) << "n " << n << " qp " << qp;
    }
}

// Squared point error (mm^2) of the decoded stream over every frame's domain pixels.
double decoded_squared_error(const std::string& stream, const std::vector<GeometryImage>& frames) {
  auto reader = GvidReader::open_memory(stream, "x.gvid");
  GVKIT_CHECK(reader.is_ok());
  GeometryError total;
  for (size_t f = 0; f < frames.size(); ++f) {
    auto decoded = (*reader)->decode_frame(static_cast<int64_t>(f));
    GVKIT_CHECK(decoded.is_ok());
    accumulate(total, geometry_error(frames[f], *decoded));
  }
  return total.sum_squared_mm2;
}

// In whole streams (I, P and B frames, both presets, every transform size): the decoder
// reproduces the encoder's reconstructions, and at the same QP RDO quantization lowers the
// stream's SSD + lambda x bits against the fixed offsets, with neither term much larger.
TEST(RdoQuantization, StreamsRoundTripAndCostLess) {
  const auto frames = testing::make_moving_analytic_video(48, 6);
  const SequenceInfo info = testing::info_for(frames);
  const double step_mm2 = info.step_mm() * info.step_mm();
  for (const Preset preset : {Preset::kFast, Preset::kSlow}) {
    EncoderOptions o;
    o.p_qp_offset = 6;  // P frames at QP 18, as measured
    o.qp = 12;
    o.preset = preset;
    o.intra_period = 4;
    double bits[2], sse[2];
    for (const bool rdoq : {false, true}) {
      o.rdoq = rdoq;
      const std::string stream = testing::writer_round_trip(frames, info, o);
      bits[rdoq] = 8.0 * static_cast<double>(stream.size());
      sse[rdoq] = decoded_squared_error(stream, frames) / step_mm2;  // in squared 16-bit steps
    }
    // RDO quantization weighs bits by half the mode decision's lambda (plane_encoder.cpp).
    const double lambda = 0.5 * lambda_of(o.qp_prime());  // the I frames' (P and B: larger)
    EXPECT_LT(sse[1] + lambda * bits[1], 0.99 * (sse[0] + lambda * bits[0])) << preset_name(preset);
    EXPECT_LT(sse[1], 1.1 * sse[0]) << preset_name(preset);
    EXPECT_LT(bits[1], 1.05 * bits[0]) << preset_name(preset);
  }
}

// Lossless and near-lossless streams have no quantizer for it: byte for byte the same.
TEST(RdoQuantization, LosslessAndNearLosslessStreamsDoNotChange) {
  const auto frames = testing::make_moving_analytic_video(32, 3);
  const SequenceInfo info = testing::info_for(frames);
  for (const double max_error : {0.0, 0.05}) {
    EncoderOptions o;
    o.lossless = max_error == 0;
    o.max_error_mm = max_error;
    o.intra_period = 2;
    o.rdoq = false;
    const std::string off = testing::writer_round_trip(frames, info, o);
    o.rdoq = true;
    EXPECT_EQ(testing::writer_round_trip(frames, info, o), off) << "max error " << max_error;
  }
}

}  // namespace
}  // namespace gvkit::codec::detail
