#include "gvkit/core/image_io.hpp"

#include <opencv2/imgcodecs.hpp>  // the flags only: the codecs are in the plugin
#include <opencv2/imgproc.hpp>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/opencv_media.hpp"

namespace gvkit {
namespace fs = std::filesystem;

Result<cv::Mat> read_image(const fs::path& path, bool grey, ImageDepth depth) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  GVKIT_ASSIGN_OR_RETURN(cv::Mat image, opencv_media::imread(path.string(), cv::IMREAD_UNCHANGED));
  if (image.empty())
    return corrupt_data(path.string() + ": not a readable image (truncated or unknown format)");
  if (image.depth() != CV_8U && image.depth() != CV_16U)
    return unsupported(path.string() + ": only 8- and 16-bit images are supported");
  if (depth == ImageDepth::k8 && image.depth() != CV_8U)
    return unsupported(path.string() + ": expected an 8-bit image");
  if (depth == ImageDepth::k16 && image.depth() != CV_16U)
    return unsupported(path.string() + ": expected a 16-bit image");
  if (grey && image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  if (grey && image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2GRAY);
  return image;
}

Status write_image(const fs::path& path, const cv::Mat& image) {
  if (image.empty()) return invalid_argument(path.string() + ": empty image");
  if ((image.depth() != CV_8U && image.depth() != CV_16U) ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    return unsupported(path.string() +
                       ": only 8/16-bit images with 1, 3 or 4 channels are written");
  return write_via_temp_file(path, [&](const fs::path& temp) -> Status {
    // The temporary name keeps the extension, so OpenCV picks the same encoder.
    const Result<bool> written = opencv_media::imwrite(temp.string(), image);
    if (!written.is_ok())  // OpenCV threw, or its codecs are missing: the message says which
      return Status(written.status().code(),
                    path.string() + ": cannot write image (" + written.status().message() + ")");
    if (!written.value()) return io_error(path.string() + ": cannot write image");
    return Status::ok();
  });
}

}  // namespace gvkit
