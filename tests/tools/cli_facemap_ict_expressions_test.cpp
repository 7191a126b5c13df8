// Every expression of the ICT-FaceKit model (a real scanned face: neutral, then each blendshape
// at full weight) through `facemap clean` (each frame on its own, from its landmark file) and
// `facemap map`: every frame maps with 0 flipped triangles, and stats.json has the per-frame
// feature drift and temporal MSE. Small geometry images keep it cheap.
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

TEST(CliFacemapIctExpressions, EveryExpressionMapsWithoutFlips) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit");
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  const int frames = 1 + static_cast<int>(model->expression_names().size());
  TempDir dir;
  auto r = run_gvkit("facemap ict-sequence " + (data / "ict-facekit").string() + " -o " +
                     (dir / "in").string() + " --program expressions");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto sequence = read_json(dir / "in" / "sequence.json");
  ASSERT_TRUE(sequence.is_ok());
  ASSERT_EQ((*sequence)["frames"].size(), static_cast<size_t>(frames));
  EXPECT_EQ((*sequence)["frames"][9]["weights"].begin().key(), model->expression_names()[8]);

  r = run_gvkit("facemap clean " + (dir / "in").string() + " -o " + (dir / "faces").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_gvkit("facemap map " + (dir / "faces").string() + " -o " + (dir / "map").string() +
                " --size 48x48");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto stats = read_json(dir / "map" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["mapped"], frames);
  EXPECT_EQ((*stats)["summary"]["flipped_total"], 0);
  for (const auto& f : (*stats)["frames"]) {
    const std::string expression =
        (*sequence)["frames"][f["index"].get<size_t>()]["weights"].empty()
            ? "neutral"
            : (*sequence)["frames"][f["index"].get<size_t>()]["weights"].begin().key();
    EXPECT_EQ(f["flipped"], 0) << expression;
    EXPECT_TRUE(f.contains("feature_drift_px")) << expression;
    // The eyes' and mouth's key points stay where the domain puts them (under a pixel).
    EXPECT_LT(f["key_feature_drift_px"]["max"].get<double>(), 1.0) << expression;
    if (f["index"] != 0) {
      EXPECT_TRUE(f.contains("temporal_mse_mean_mm2")) << expression;
    }
  }
}

}  // namespace
}  // namespace gvkit
