#include "gvkit/core/exr_io.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <gtest/gtest.h>

#include "exr_zip_chunk.hpp"
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

// Planes that ZIP shortens (runs, a ramp) and planes it cannot (noise), with NaNs.
ExrChannels mixed_planes(cv::Size size) {
  ExrChannels planes{{"M", cv::Mat(size, CV_32F, cv::Scalar(1))},
                     {"X", random_plane(size, 21)},
                     {"Y", cv::Mat(size, CV_32F)},
                     {"Z", random_plane(size, 22)}};
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) planes["Y"].at<float>(y, x) = 0.25f * x - y;
  planes["M"](cv::Rect(0, 0, size.width / 2, size.height / 3)) = 0.0f;
  planes["Z"].at<float>(size.height - 1, 0) = NAN;
  return planes;
}

// The planes of a file as OpenEXR's own decoder reads them.
ExrChannels read_with_openexr(const fs::path& path) {
  Imf::InputFile file(path.c_str());
  const Imath::Box2i w = file.header().dataWindow();
  const cv::Size size(w.max.x - w.min.x + 1, w.max.y - w.min.y + 1);
  ExrChannels planes;
  Imf::FrameBuffer frame_buffer;
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
    cv::Mat plane(size, CV_32F);
    frame_buffer.insert(it.name(), Imf::Slice(Imf::FLOAT,
                                              reinterpret_cast<char*>(plane.data) -
                                                  w.min.x * sizeof(float) - w.min.y * plane.step[0],
                                              sizeof(float), plane.step[0]));
    planes[it.name()] = plane;
  }
  file.setFrameBuffer(frame_buffer);
  file.readPixels(w.min.y, w.max.y);
  return planes;
}

// write_exr's ZIP files (chunks deflated by libdeflate) read back through OpenEXR's own
// decoder, and OpenEXR's own ZIP and ZIPS files (chunks of 16 and of 1 line, a data window not
// at the origin, chunks stored top down and bottom up) read through read_exr's chunk decoding,
// bit for bit; heights that are not a multiple of 16 end in a shorter chunk.
TEST(ExrIo, ZipChunksMatchOpenExrsOwnCoding) {
  TempDir dir;
  for (const cv::Size size : {cv::Size(37, 23), cv::Size(320, 32), cv::Size(1, 1)}) {
    const ExrChannels planes = mixed_planes(size);
    ASSERT_TRUE(write_exr(dir / "ours.exr", planes, ExrCompression::kZip).is_ok());
    const ExrChannels back = read_with_openexr(dir / "ours.exr");
    ASSERT_EQ(back.size(), planes.size());
    for (const auto& [name, plane] : planes)
      EXPECT_TRUE(same_bits(back.at(name), plane)) << name << " " << size;

    for (const Imf::Compression compression : {Imf::ZIP_COMPRESSION, Imf::ZIPS_COMPRESSION})
      for (const Imf::LineOrder order : {Imf::INCREASING_Y, Imf::DECREASING_Y}) {
        const Imath::Box2i window({5, -3}, {5 + size.width - 1, -3 + size.height - 1});
        Imf::Header header(window, window);
        header.compression() = compression;
        header.lineOrder() = order;
        Imf::FrameBuffer frame_buffer;
        for (const auto& [name, plane] : planes) {
          header.channels().insert(name, Imf::Channel(Imf::FLOAT));
          frame_buffer.insert(name, Imf::Slice(Imf::FLOAT,
                                               reinterpret_cast<char*>(plane.data) -
                                                   5 * sizeof(float) + 3 * plane.step[0],
                                               sizeof(float), plane.step[0]));
        }
        {
          Imf::OutputFile file((dir / "theirs.exr").c_str(), header);
          file.setFrameBuffer(frame_buffer);
          file.writePixels(size.height);
        }
        auto read = read_exr(dir / "theirs.exr");
        ASSERT_TRUE(read.is_ok()) << read.status().message();
        for (const auto& [name, plane] : planes)
          EXPECT_TRUE(same_bits(read->at(name), plane))
              << name << " " << size << " " << compression << " " << order;
      }
  }
}

// A tiled ZIP file of float channels is not read chunk by chunk but through OpenEXR's decoding:
// the same floats.
TEST(ExrIo, TiledZipFileReadsThroughOpenExr) {
  TempDir dir;
  const ExrChannels planes = mixed_planes({37, 23});
  Imf::Header header(37, 23);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.setTileDescription(Imf::TileDescription(16, 16, Imf::ONE_LEVEL));
  Imf::FrameBuffer frame_buffer;
  for (const auto& [name, plane] : planes) {
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    frame_buffer.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(plane.data),
                                         sizeof(float), plane.step[0]));
  }
  {
    Imf::TiledOutputFile file((dir / "tiled.exr").c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writeTiles(0, file.numXTiles() - 1, 0, file.numYTiles() - 1);
  }
  auto read = read_exr(dir / "tiled.exr");
  ASSERT_TRUE(read.is_ok()) << read.status().message();
  for (const auto& [name, plane] : planes) EXPECT_TRUE(same_bits(read->at(name), plane)) << name;
}

// The chunk coder on sizes the SIMD passes split unevenly (odd, below and above 16 and 32
// bytes): unpack(pack(x)) == x, and a stream that is cut, altered or for another size is refused.
TEST(ExrIo, ZipChunkCoderRoundTripsAndRefusesDamagedChunks) {
  detail::ExrZipChunkCoder coder;
  cv::RNG rng(5);
  for (const size_t size : {1u, 2u, 15u, 16u, 17u, 31u, 33u, 64u, 65u, 1000u, 4099u}) {
    for (const bool compressible : {true, false}) {
      std::vector<uint8_t> raw(size);
      for (size_t i = 0; i < size; ++i)
        raw[i] = static_cast<uint8_t>(compressible ? i / 7 : rng.uniform(0, 256));
      const std::vector<uint8_t> packed = coder.pack(raw.data(), size);
      EXPECT_LE(packed.size(), size);
      if (compressible && size >= 64) {
        EXPECT_LT(packed.size(), size / 2) << size;
      }
      std::vector<uint8_t> back(size, 0xaa);
      ASSERT_TRUE(coder.unpack(packed.data(), packed.size(), back.data(), size)) << size;
      EXPECT_EQ(back, raw) << size << " " << compressible;
      if (packed.size() == size) continue;  // stored as is: nothing to damage
      EXPECT_FALSE(coder.unpack(packed.data(), packed.size() - 1, back.data(), size));
      std::vector<uint8_t> altered = packed;
      altered[altered.size() / 2] ^= 0x10;
      EXPECT_FALSE(coder.unpack(altered.data(), altered.size(), back.data(), size));
      std::vector<uint8_t> bigger(size + 1);
      EXPECT_FALSE(coder.unpack(packed.data(), packed.size(), bigger.data(), size + 1));
    }
  }
}

TEST(ExrIo, DamagedZipChunkIsNamedInTheError) {
  TempDir dir;
  ASSERT_TRUE(write_exr(dir / "full.exr", mixed_planes({64, 64}), ExrCompression::kZip).is_ok());
  std::string bytes = *read_file(dir / "full.exr");
  bytes[bytes.size() - 100] ^= 0x55;  // inside the last chunk's zlib stream
  ASSERT_TRUE(write_file_atomically(dir / "damaged.exr", bytes).is_ok());
  auto damaged = read_exr(dir / "damaged.exr");
  ASSERT_FALSE(damaged.is_ok());
  EXPECT_EQ(damaged.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(damaged.status().message().find("damaged.exr"), std::string::npos);
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
