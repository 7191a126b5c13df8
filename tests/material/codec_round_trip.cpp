#include "codec_round_trip.hpp"

#include <unistd.h>
#include <atomic>
#include <cstring>
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::testing {

codec::SequenceInfo info_for(const std::vector<GeometryImage>& frames, int bit_depth) {
  auto info = codec::make_sequence_info(frames, bit_depth, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

bool same_samples(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty();
  if (a.size() != b.size() || a.type() != b.type()) return false;
  const size_t row_bytes = static_cast<size_t>(a.cols) * a.elemSize();
  for (int y = 0; y < a.rows; ++y)
    if (std::memcmp(a.ptr(y), b.ptr(y), row_bytes) != 0) return false;
  return true;
}

std::string writer_round_trip(const std::vector<GeometryImage>& frames,
                              const codec::SequenceInfo& info, const codec::EncoderOptions& options,
                              std::vector<codec::FrameCodingStats>* stats) {
  static std::atomic<int> calls{0};
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("gvkit_round_trip_" + std::to_string(::getpid()) + "_" + std::to_string(calls++));
  std::filesystem::create_directories(dir);
  const auto path = dir / "x.gvid";
  std::vector<GeometryImage> recon;
  {
    auto writer = codec::GvidWriter::create(path, info, options);
    GVKIT_CHECK(writer.is_ok(), writer.status().message());
    for (const auto& f : frames) {
      auto done = (*writer)->write(f);
      GVKIT_CHECK(done.is_ok(), done.status().message());
      for (auto& r : *done) recon.push_back(std::move(r));
    }
    auto rest = (*writer)->finish();
    GVKIT_CHECK(rest.is_ok(), rest.status().message());
    for (auto& r : *rest) recon.push_back(std::move(r));
    if (stats) *stats = (*writer)->frame_stats();
  }
  auto bytes = read_file(path);
  std::filesystem::remove_all(dir);
  GVKIT_CHECK(bytes.is_ok());
  auto reader = codec::GvidReader::open_memory(*bytes, "x.gvid");
  EXPECT_TRUE(reader.is_ok()) << reader.status().message();
  if (!reader.is_ok()) return *bytes;
  EXPECT_EQ((*reader)->frame_count(), static_cast<int64_t>(frames.size()));
  for (size_t f = 0; f < frames.size() && f < recon.size(); ++f) {
    auto decoded = (*reader)->decode_frame(static_cast<int64_t>(f));
    EXPECT_TRUE(decoded.is_ok()) << decoded.status().message();
    if (decoded.is_ok()) {
      EXPECT_TRUE(same_samples(decoded->xyz_mm, recon[f].xyz_mm)) << "frame " << f;
    }
  }
  return *bytes;
}

double stream_psnr_db(const std::vector<GeometryImage>& frames, const codec::SequenceInfo& info,
                      const std::string& stream) {
  auto reader = codec::GvidReader::open_memory(stream, "x.gvid").value();
  codec::GeometryError total;
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    codec::accumulate(total, codec::geometry_error(frames[static_cast<size_t>(f)],
                                                   reader->decode_frame(f).value()));
  return total.psnr_db(info.box_diagonal_mm());
}

std::vector<std::pair<std::string, codec::EncoderOptions>> p_frame_cases() {
  std::vector<std::pair<std::string, codec::EncoderOptions>> cases;
  for (const codec::Preset preset : {codec::Preset::kFast, codec::Preset::kSlow})
    for (const int bframes : {0, 1})
      for (const int qp : {0, 12}) {
        codec::EncoderOptions o;
        o.preset = preset;
        o.bframes = bframes;
        o.qp = qp;
        o.intra_period = 5;
        o.threads = 2;
        cases.push_back({std::string(codec::preset_name(preset)) + " bframes " +
                             std::to_string(bframes) + " qp " + std::to_string(qp),
                         o});
      }
  codec::EncoderOptions refs1 = cases[0].second;
  refs1.refs = 1;
  cases.push_back({"fast refs 1", refs1});
  codec::EncoderOptions shared = cases[4].second;  // slow, no B frames, QP 0
  shared.shared_motion = true;
  shared.joint_motion_search = true;
  cases.push_back({"slow shared motion", shared});
  codec::EncoderOptions lossless;
  lossless.lossless = true;
  lossless.preset = codec::Preset::kFast;
  cases.push_back({"lossless", lossless});
  codec::EncoderOptions bounded;
  bounded.max_error_mm = 0.05;
  bounded.preset = codec::Preset::kFast;
  cases.push_back({"near-lossless", bounded});
  return cases;
}

}  // namespace gvkit::testing
