// Encodes a folder of geometry-image EXRs (frame_NNNNNN.exr, as `gvkit facemap map` writes them)
// into a .gvid geometry video.
//   encode_folder GV_FOLDER OUT.gvid [QP]
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <gvkit/codec/gvid_writer.hpp>
#include <gvkit/core/exr_io.hpp>
#include <gvkit/core/frame_files.hpp>

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s GV_FOLDER OUT.gvid [QP]\n", argv[0]);
    return 2;
  }
  auto fail = [](const gvkit::Status& s) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return 1;
  };
  const auto files = gvkit::list_frame_files(argv[1], ".exr");
  if (!files.is_ok()) return fail(files.status());
  if (files->empty()) return fail(gvkit::not_found(std::string(argv[1]) + ": no frame_NNNNNN.exr"));
  std::vector<gvkit::GeometryImage> frames;
  for (const auto& f : *files) {
    auto image = gvkit::read_geometry_image_exr(f.path);
    if (!image.is_ok()) return fail(image.status());
    frames.push_back(std::move(image).value());
  }
  gvkit::codec::EncoderOptions options;  // 16-bit samples, P frames, the slow (RDO) preset
  if (argc == 4) options.qp = std::atoi(argv[3]);
  auto info = gvkit::codec::make_sequence_info(frames, options.bit_depth, 30.0);
  if (!info.is_ok()) return fail(info.status());
  auto writer = gvkit::codec::GvidWriter::create(argv[2], *info, options);
  if (!writer.is_ok()) return fail(writer.status());
  for (const auto& frame : frames)
    if (auto decoded = (*writer)->write(frame); !decoded.is_ok()) return fail(decoded.status());
  if (auto rest = (*writer)->finish(); !rest.is_ok()) return fail(rest.status());
  int64_t bytes = (*writer)->header_bytes();
  for (int64_t b : (*writer)->frame_bytes()) bytes += b;
  std::printf("%zu frames %dx%d -> %s, %lld bytes\n", frames.size(), info->width, info->height,
              argv[2], static_cast<long long>(bytes));
  return 0;
}
