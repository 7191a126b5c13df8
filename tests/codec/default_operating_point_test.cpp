// The default encode looks like its input (issue 30): a smooth surface at a face's pixel spacing
// (an ellipsoidal dome with a nose-like bump, smooth folds of 16 to 22 pixels and a mouth-like
// hole, moving a little from frame to frame), coded with EncoderOptions' defaults, keeps the
// 95th-percentile normal error within the threshold the default QP was chosen for (2 degrees at
// the metric's default 2-pixel scale, docs/benchmarks.md "Surface metrics") and its outline
// within 0.4 pixel of the input's; the former default QP 12 fails both bounds on the same
// surface, so the test can fail. The outline weight (EncoderOptions::outline_weight) is what keeps
// the outline closer than the interior.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/surface_metrics.hpp"

namespace gvkit::codec {
namespace {

constexpr int kSize = 128;             // pixels per side
constexpr double kSpacingMm = 0.65;    // the main job's pixel spacing on the face
constexpr double kNormalP95Deg = 2.0;  // the threshold of the default QP
constexpr double kOutlineMm = 0.25;    // 0.4 pixel

GeometryImage surface(int frame) {
  GeometryImage g;
  g.xyz_mm.create(kSize, kSize, CV_32FC3);
  g.domain_mask.create(kSize, kSize, CV_8U);
  const double shift = 0.5 * frame, nose = 1.0 * frame;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double u = (x - (kSize - 1) / 2.0) * kSpacingMm,
                   v = (y - (kSize - 1) / 2.0) * kSpacingMm;
      const double a = u / 90.0, b = v / 110.0;
      const double dome = 45.0 * std::sqrt(1.0 - a * a - b * b);
      const double bump =
          15.0 * std::exp(-((u - nose) * (u - nose) / 64.0 + (v + 5.0) * (v + 5.0) / 150.0));
      // Smooth folds of 10 to 20 pixels, as skin has.
      const double folds = 0.4 * std::sin(u / 1.7 + 0.3 * v) + 0.3 * std::sin(v / 2.3 - 0.2 * u);
      g.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(u + shift), static_cast<float>(v),
                                               static_cast<float>(650.0 - dome - bump - folds));
      const double mu = u / 14.0, mv = (v - 22.0) / 4.0;  // the mouth
      g.domain_mask.at<uint8_t>(y, x) = mu * mu + mv * mv <= 1.0 ? 0 : 255;
    }
  return g;
}

SurfaceError coded_error(const EncoderOptions& options) {
  std::vector<GeometryImage> frames;
  for (int f = 0; f < 3; ++f) frames.push_back(surface(f));  // I, B, P with the defaults
  const SequenceInfo info = make_sequence_info(frames, options.bit_depth, 30.0).value();
  const std::string stream = encode_gvid(frames, info, options).value();
  auto reader = GvidReader::open_memory(stream, "smooth.gvid").value();
  SurfaceError total;
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    accumulate(total, surface_error(frames[f], reader->decode_frame(f).value()));
  return total;
}

TEST(DefaultOperatingPoint, SmoothSurfaceKeepsItsNormalsAndOutline) {
  const SurfaceError e = coded_error(EncoderOptions());
  EXPECT_GT(e.normal_pixels, kSize * kSize / 2);
  EXPECT_LE(e.normal_p95_deg(), kNormalP95Deg);
  EXPECT_LE(e.outline_hausdorff_mm, kOutlineMm);
  EXPECT_LE(e.hausdorff_mm, kOutlineMm);

  EncoderOptions former;
  former.qp = 12;
  const SurfaceError coarse = coded_error(former);
  EXPECT_GT(coarse.normal_p95_deg(), kNormalP95Deg);
  EXPECT_GT(coarse.outline_hausdorff_mm, kOutlineMm);
}

TEST(DefaultOperatingPoint, OutlineWeightKeepsTheOutlineCloser) {
  EncoderOptions weighted;
  weighted.qp = 0;
  EncoderOptions plain = weighted;
  plain.outline_weight = 1;
  const SurfaceError w = coded_error(weighted), p = coded_error(plain);
  EXPECT_LT(w.outline_hausdorff_mm, 0.85 * p.outline_hausdorff_mm);  // 0.22 against 0.30 mm
  EXPECT_LE(w.normal_p95_deg(), 1.1 * p.normal_p95_deg());
  plain.outline_weight = 0;
  EXPECT_NE(plain.check().message().find("outline weight 0"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::codec
