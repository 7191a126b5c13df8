// Decodes a .gvid geometry video and prints, per frame, its type, size and the extent of the
// decoded surface; a damaged frame is named and the others are still decoded.
//   decode_stats FILE.gvid
#include <algorithm>
#include <cstdio>

#include <gvkit/codec/gvid_reader.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE.gvid\n", argv[0]);
    return 2;
  }
  auto reader = gvkit::codec::GvidReader::open(argv[1]);
  if (!reader.is_ok()) {
    std::fprintf(stderr, "error: %s\n", reader.status().message().c_str());
    return 1;
  }
  auto& r = **reader;
  const int64_t vertices = r.info().domain_pixels();
  std::printf("%s: %lld frames %dx%d, %lld vertices per frame\n", argv[1],
              static_cast<long long>(r.frame_count()), r.info().width, r.info().height,
              static_cast<long long>(vertices));
  std::printf("%6s %5s %9s %10s  %s\n", "frame", "type", "bits", "bits/vtx", "z range (mm)");
  int failed = 0;
  for (int64_t i = 0; i < r.frame_count(); ++i) {
    const bool intra = r.frame_type(i) == gvkit::codec::format::FrameType::kIntra;
    std::printf("%6lld %5s %9lld %10.4f  ", static_cast<long long>(i), intra ? "I" : "P",
                static_cast<long long>(r.frame_bits(i)),
                static_cast<double>(r.frame_bits(i)) / static_cast<double>(vertices));
    auto frame = r.decode_frame(i);
    if (!frame.is_ok()) {
      std::printf("failed: %s\n", frame.status().message().c_str());
      ++failed;
      continue;
    }
    double z_min = 1e300, z_max = -1e300;
    for (int y = 0; y < frame->xyz_mm.rows; ++y)
      for (int x = 0; x < frame->xyz_mm.cols; ++x)
        if (frame->domain_mask.at<uint8_t>(y, x)) {
          const double z = frame->xyz_mm.at<cv::Vec3f>(y, x)[2];
          z_min = std::min(z_min, z);
          z_max = std::max(z_max, z);
        }
    std::printf("%.2f .. %.2f\n", z_min, z_max);
  }
  if (failed)
    std::fprintf(stderr, "%d of %lld frames failed\n", failed,
                 static_cast<long long>(r.frame_count()));
  return failed ? 1 : 0;
}
