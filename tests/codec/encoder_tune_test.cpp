// Tune keys (encoder_tune.hpp): every key takes a value of its documented kind and sets its
// option, bad keys and values are rejected naming them, ranges are left to
// EncoderOptions::check(), and docs/encoding.md lists every key.
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "gvkit/codec/encoder_tune.hpp"

namespace gvkit::codec {
namespace {

bool has(const Status& s, const std::string& text) {
  return s.message().find(text) != std::string::npos;
}

// A value of each key that differs from the default and passes check().
const std::map<std::string, std::string> kSamples = {
    {"geometry-modes", "off"},
    {"td", "no"},
    {"td16", "false"},
    {"merge", "0"},
    {"quadratic-intra", "off"},
    {"cross-plane", "off"},
    {"cross-plane-contexts", "off"},
    {"temporal-contexts", "off"},
    {"partitions", "off"},
    {"deblock", "off"},
    {"deblock-beta", "9"},
    {"deblock-tc", "2"},
    {"max-transform", "8"},
    {"resolution", "half"},
    {"bframes", "2"},
    {"refs", "5"},
    {"subpel", "2"},
    {"shared-motion", "on"},
    {"value-prediction", "affine"},
    {"plane-qp-offsets", "-1,0,2"},
    {"p-qp-offset", "6"},
    {"b-qp-offset", "3"},
    {"search-range", "8"},
    {"rdoq", "off"},
    {"intra-rdo", "off"},
    {"decimation", "off"},
    {"joint-motion-search", "on"},
    {"skip-check", "yes"},
    {"td-whole-retry", "on"},
    {"texture-qp", "30"},
    {"outline-weight", "3"},
    {"rdo-shortlist", "2"},
    {"transform-early-exit", "on"},
    {"buffer-seconds", "2.5"},
    {"target-rms-mm", "0.1"},
    {"intra-target-offset", "2"},
};

// Every field a tune key sets, as text.
std::string fields(const EncoderOptions& o) {
  std::ostringstream s;
  s << o.geometry_modes << o.td_prediction << o.td16 << o.merge << o.quadratic_intra
    << o.cross_plane << o.cross_plane_contexts << o.temporal_contexts << o.partitions
    << o.deblocking << ' ' << o.deblock.beta << ' ' << o.deblock.tc << ' ' << o.max_transform << ' '
    << static_cast<int>(o.resolution) << ' ' << o.bframes << ' ' << o.refs << ' ' << o.subpel
    << o.shared_motion << static_cast<int>(o.value_prediction) << ' ' << o.plane_qp_offset[0] << ' '
    << o.plane_qp_offset[1] << ' ' << o.plane_qp_offset[2] << ' ' << o.p_qp_offset << ' '
    << o.b_qp_offset << ' ' << o.search_range << o.rdoq << o.intra_rdo << o.inter_decimation
    << o.joint_motion_search << o.skip_check << o.td_whole_retry << ' ' << o.rdo_shortlist
    << o.transform_early_exit << ' ' << o.outline_weight << ' ' << o.texture_qp << ' '
    << o.buffer_seconds << ' ' << o.target_rms_mm << ' ' << o.intra_target_offset_db;
  return s.str();
}

TEST(EncoderTune, EveryKeySetsItsOption) {
  ASSERT_EQ(tune_keys().size(), kSamples.size());
  const EncoderOptions defaults;
  for (const TuneKey& k : tune_keys()) {
    SCOPED_TRACE(k.name);
    ASSERT_TRUE(kSamples.count(k.name)) << "no sample value";
    EncoderOptions o;
    ASSERT_TRUE(apply_tune(std::string(k.name) + "=" + kSamples.at(k.name), &o).is_ok());
    EXPECT_TRUE(o.check().is_ok()) << o.check().message();
    EXPECT_NE(fields(o), fields(defaults));  // the key reached its option
  }
  EncoderOptions o;
  ASSERT_TRUE(apply_tune("plane-qp-offsets", "-1,0,2", &o).is_ok());
  EXPECT_EQ(o.plane_qp_offset[0], -1);
  EXPECT_EQ(o.plane_qp_offset[2], 2);
  ASSERT_TRUE(apply_tune("resolution=full", &o).is_ok());
  EXPECT_EQ(o.resolution, Resolution::kFull);
  ASSERT_TRUE(apply_tune("merge", "off", &o).is_ok());
  EXPECT_FALSE(o.merge);
}

TEST(EncoderTune, BadKeysAndValuesAreRejectedNamingThem) {
  EncoderOptions o;
  const EncoderOptions before = o;
  const std::pair<const char*, const char*> cases[] = {
      {"merge=maybe", "tune merge=maybe: not on or off (on|off)"},
      {"frobnicate=1", "tune frobnicate=1: unknown key"},
      {"merge", "tune 'merge': not key=value"},
      {"=on", "tune '=on': not key=value"},
      {"refs=three", "tune refs=three: not an integer"},
      {"refs=", "tune refs=: not an integer"},
      {"buffer-seconds=1s", "tune buffer-seconds=1s: not a number"},
      {"resolution=quarter", "resolution 'quarter' unknown"},
      {"value-prediction=rigid", "value prediction 'rigid' unknown"},
      {"plane-qp-offsets=1,2", "three integers X,Y,Z"},
      {"plane-qp-offsets=1,2,3,4", "three integers X,Y,Z"},
  };
  for (const auto& [tune, message] : cases) {
    const Status s = apply_tune(tune, &o);
    ASSERT_FALSE(s.is_ok()) << tune;
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_TRUE(has(s, message)) << s.message();
  }
  EXPECT_EQ(o.merge, before.merge);  // a failed tune changes nothing
  EXPECT_EQ(o.refs, before.refs);
  // Parsed, then out of range: check() names the option.
  ASSERT_TRUE(apply_tune("refs=9", &o).is_ok());
  EXPECT_TRUE(has(o.check(), "refs 9 out of range")) << o.check().message();
}

TEST(EncoderTune, TheEncodingPageListsEveryKey) {
  std::ifstream in(GVKIT_SOURCE_DIR "/docs/encoding.md");
  ASSERT_TRUE(in) << "docs/encoding.md";
  std::stringstream page;
  page << in.rdbuf();
  for (const TuneKey& k : tune_keys())
    EXPECT_NE(page.str().find(std::string("| `") + k.name + "` |"), std::string::npos)
        << k.name << " is missing from the table in docs/encoding.md";
}

}  // namespace
}  // namespace gvkit::codec
