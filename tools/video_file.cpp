#include "video_file.hpp"

namespace gvkit::tools {

Result<std::string> open_video(cv::VideoWriter& writer, const std::filesystem::path& path,
                               double fps, cv::Size size) {
  for (const char* cc : {"avc1", "mp4v"}) {
    if (writer.open(path.string(), cv::CAP_FFMPEG,
                    cv::VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), fps, size))
      return std::string(cc);
  }
  return io_error(path.string() + ": cannot open a video writer (FFmpeg: avc1 and mp4v failed)");
}

}  // namespace gvkit::tools
