#include "video_file.hpp"

#include <opencv2/videoio.hpp>  // the constants only: the codecs are in the plugin

namespace gvkit::tools {

Result<std::string> open_video(opencv_media::VideoWriter& writer, const std::filesystem::path& path,
                               double fps, cv::Size size) {
  GVKIT_RETURN_IF_ERROR(opencv_media::load());
  for (const char* cc : {"avc1", "mp4v"}) {
    if (writer
            .open(path.string(), cv::CAP_FFMPEG, opencv_media::fourcc(cc[0], cc[1], cc[2], cc[3]),
                  fps, size)
            .is_ok())
      return std::string(cc);
  }
  return io_error(path.string() + ": cannot open a video writer (FFmpeg: avc1 and mp4v failed)");
}

}  // namespace gvkit::tools
