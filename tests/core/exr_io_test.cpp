#include "gvkit/core/exr_io.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;

cv::Mat random_plane(cv::Size size, int seed) {
  cv::Mat m(size, CV_32F);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, -1000.0, 1000.0);
  return m;
}

bool same_bits(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::equal(a.begin<float>(), a.end<float>(), b.begin<float>(),
                    [](float x, float y) { return (std::isnan(x) && std::isnan(y)) || x == y; });
}

TEST(ExrIo, ChannelsRoundTripBitExactly) {
  TempDir dir;
  ExrChannels channels{{"A", random_plane({37, 23}, 1)}, {"B", random_plane({37, 23}, 2)}};
  channels["A"].at<float>(3, 4) = NAN;
  ASSERT_TRUE(write_exr(dir / "c.exr", channels).is_ok());
  auto back = read_exr(dir / "c.exr");
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  ASSERT_EQ(back->size(), 2u);
  EXPECT_TRUE(same_bits(back->at("A"), channels["A"]));
  EXPECT_TRUE(same_bits(back->at("B"), channels["B"]));
}

TEST(ExrIo, EveryCompressionRoundTripsBitExactly) {
  TempDir dir;
  // Runs of equal values (which RLE and ZIP shorten) beside noise (which they cannot).
  cv::Mat runs(64, 48, CV_32F, cv::Scalar(0.0f));
  runs(cv::Rect(10, 5, 20, 30)).setTo(1.0f);
  ExrChannels channels{{"N", random_plane({48, 64}, 12)}, {"R", runs}};
  channels["N"].at<float>(7, 9) = NAN;
  std::map<ExrCompression, uintmax_t> sizes;
  for (const ExrCompression c :
       {ExrCompression::kZip, ExrCompression::kRle, ExrCompression::kNone}) {
    const std::string name = exr_compression_name(c);
    const auto path = dir / (name + ".exr");
    ASSERT_TRUE(write_exr(path, channels, c).is_ok()) << name;
    auto back = read_exr(path);
    ASSERT_TRUE(back.is_ok()) << name << ": " << back.status().message();
    EXPECT_TRUE(same_bits(back->at("N"), channels["N"])) << name;
    EXPECT_TRUE(same_bits(back->at("R"), channels["R"])) << name;
    sizes[c] = fs::file_size(path);
    auto parsed = parse_exr_compression(name);
    ASSERT_TRUE(parsed.is_ok()) << name;
    EXPECT_EQ(*parsed, c);
  }
  // Compression is what the name says: ZIP smaller than RLE, RLE smaller than none.
  EXPECT_LT(sizes[ExrCompression::kZip], sizes[ExrCompression::kRle]);
  EXPECT_LT(sizes[ExrCompression::kRle], sizes[ExrCompression::kNone]);
  auto bad = parse_exr_compression("piz");
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("'piz'"), std::string::npos);
}

TEST(ExrIo, RangeScanRoundTrip) {
  TempDir dir;
  RangeScan scan;
  const cv::Size size(16, 12);
  std::vector<cv::Mat> xyz{random_plane(size, 3), random_plane(size, 4), random_plane(size, 5)};
  cv::merge(xyz, scan.xyz_mm);
  scan.valid = cv::Mat(size, CV_8U, cv::Scalar(255));
  scan.valid.at<uint8_t>(2, 2) = 0;
  scan.xyz_mm.at<cv::Vec3f>(2, 2) = cv::Vec3f(NAN, NAN, NAN);
  scan.texture = random_plane(size, 6);
  scan.quality = random_plane(size, 7);
  ASSERT_TRUE(write_range_scan_exr(dir / "s.exr", scan).is_ok());
  auto back = read_range_scan_exr(dir / "s.exr");
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  EXPECT_EQ(cv::countNonZero(back->valid != scan.valid), 0);
  EXPECT_TRUE(same_bits(back->texture, scan.texture));
  EXPECT_TRUE(same_bits(back->quality, scan.quality));
  EXPECT_TRUE(same_bits(back->xyz_mm.reshape(1), scan.xyz_mm.reshape(1)));
}

TEST(ExrIo, GeometryImageRoundTripWithAndWithoutTexture) {
  TempDir dir;
  GeometryImage gi;
  const cv::Size size(8, 8);
  cv::merge(
      std::vector<cv::Mat>{random_plane(size, 8), random_plane(size, 9), random_plane(size, 10)},
      gi.xyz_mm);
  gi.domain_mask = cv::Mat(size, CV_8U, cv::Scalar(255));
  gi.domain_mask(cv::Rect(2, 2, 3, 3)).setTo(0);
  ASSERT_TRUE(write_geometry_image_exr(dir / "g.exr", gi).is_ok());
  auto back = read_geometry_image_exr(dir / "g.exr");
  ASSERT_TRUE(back.is_ok());
  EXPECT_TRUE(back->texture.empty());
  EXPECT_EQ(cv::countNonZero(back->domain_mask), 64 - 9);
  gi.texture = random_plane(size, 11);
  ASSERT_TRUE(write_geometry_image_exr(dir / "g.exr", gi).is_ok());
  back = read_geometry_image_exr(dir / "g.exr");
  ASSERT_TRUE(back.is_ok());
  EXPECT_TRUE(same_bits(back->texture, gi.texture));
}

TEST(ExrIo, BadFilesAreNamedInTheError) {
  TempDir dir;
  auto missing = read_exr(dir / "missing.exr");
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("missing.exr"), std::string::npos);

  ASSERT_TRUE(write_file_atomically(dir / "garbage.exr", "this is not an EXR file").is_ok());
  auto garbage = read_exr(dir / "garbage.exr");
  EXPECT_EQ(garbage.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(garbage.status().message().find("garbage.exr"), std::string::npos);

  ExrChannels channels{{"X", random_plane({64, 64}, 12)}};
  ASSERT_TRUE(write_exr(dir / "full.exr", channels).is_ok());
  std::string bytes = *read_file(dir / "full.exr");
  ASSERT_TRUE(write_file_atomically(dir / "cut.exr", bytes.substr(0, bytes.size() / 2)).is_ok());
  auto cut = read_exr(dir / "cut.exr");
  EXPECT_FALSE(cut.is_ok());
  EXPECT_NE(cut.status().message().find("cut.exr"), std::string::npos);
}

TEST(ExrIo, RangeScanWithoutMaskChannelIsRejected) {
  TempDir dir;
  ExrChannels channels{{"X", random_plane({4, 4}, 1)},
                       {"Y", random_plane({4, 4}, 2)},
                       {"Z", random_plane({4, 4}, 3)}};
  ASSERT_TRUE(write_exr(dir / "nomask.exr", channels).is_ok());
  auto scan = read_range_scan_exr(dir / "nomask.exr");
  EXPECT_NE(scan.status().message().find("missing channel M"), std::string::npos);
}

TEST(ExrIo, FailedWriteLeavesNothingBehind) {
  TempDir dir;
  ExrChannels mismatched{{"A", random_plane({4, 4}, 1)}, {"B", random_plane({5, 4}, 2)}};
  EXPECT_FALSE(write_exr(dir / "bad.exr", mismatched).is_ok());
  EXPECT_FALSE(
      write_exr(dir / "no-such-folder" / "x.exr", {{"A", random_plane({4, 4}, 1)}}).is_ok());
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace gvkit
