// libgvkit_opencv_media.so: OpenCV's imgcodecs and videoio behind the table of
// opencv_media_table.hpp. The only code of the project that links those two modules.
#include <exception>
#include <memory>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "opencv_media_table.hpp"

namespace gvkit::detail {
namespace {

// Runs f; what it throws becomes false and a message.
template <typename F>
bool guarded(std::string* error, F&& f) {
  try {
    f();
    return true;
  } catch (const std::exception& e) {
    *error = e.what();
  } catch (...) {
    *error = "unknown exception";
  }
  return false;
}

bool imread(const std::string& path, int flags, cv::Mat* out, std::string* error) {
  return guarded(error, [&] { *out = cv::imread(path, flags); });
}

bool imdecode(const cv::Mat& data, int flags, cv::Mat* out, std::string* error) {
  return guarded(error, [&] { *out = cv::imdecode(data, flags); });
}

bool imwrite(const std::string& path, const cv::Mat& image, const std::vector<int>& params,
             bool* done, std::string* error) {
  return guarded(error, [&] { *done = cv::imwrite(path, image, params); });
}

bool imencode(const std::string& extension, const cv::Mat& image, const std::vector<int>& params,
              std::vector<uint8_t>* out, bool* done, std::string* error) {
  return guarded(error, [&] { *done = cv::imencode(extension, image, *out, params); });
}

void* writer_open(const std::string& path, int api, int fourcc, double fps, int width, int height,
                  std::string* error) {
  auto writer = std::make_unique<cv::VideoWriter>();
  bool opened = false;
  if (!guarded(error,
               [&] {
                 opened = writer->open(path, api, fourcc, fps, {width, height});
               }) ||
      !opened)
    return nullptr;
  return writer.release();
}

bool writer_write(void* writer, const cv::Mat& picture, std::string* error) {
  return guarded(error, [&] { static_cast<cv::VideoWriter*>(writer)->write(picture); });
}

void writer_close(void* writer) {
  auto* w = static_cast<cv::VideoWriter*>(writer);
  std::string ignored;
  guarded(&ignored, [&] { w->release(); });
  delete w;
}

void* capture_open(const std::string& path, int api, std::string* error) {
  auto capture = std::make_unique<cv::VideoCapture>();
  bool opened = false;
  if (!guarded(error, [&] { opened = capture->open(path, api); }) || !opened) return nullptr;
  return capture.release();
}

bool capture_read(void* capture, cv::Mat* picture, std::string* error) {
  bool read = false;
  return guarded(error, [&] { read = static_cast<cv::VideoCapture*>(capture)->read(*picture); }) &&
         read;
}

double capture_get(void* capture, int property) {
  double value = 0;
  std::string ignored;
  guarded(&ignored, [&] { value = static_cast<cv::VideoCapture*>(capture)->get(property); });
  return value;
}

bool capture_set(void* capture, int property, double value) {
  bool set = false;
  std::string ignored;
  guarded(&ignored, [&] { set = static_cast<cv::VideoCapture*>(capture)->set(property, value); });
  return set;
}

void capture_close(void* capture) {
  auto* c = static_cast<cv::VideoCapture*>(capture);
  std::string ignored;
  guarded(&ignored, [&] { c->release(); });
  delete c;
}

constexpr OpenCvMediaTable kTable = {
    .abi = kOpenCvMediaAbi,
    .size = sizeof(OpenCvMediaTable),
    .imread = imread,
    .imdecode = imdecode,
    .imwrite = imwrite,
    .imencode = imencode,
    .writer_open = writer_open,
    .writer_write = writer_write,
    .writer_close = writer_close,
    .capture_open = capture_open,
    .capture_read = capture_read,
    .capture_get = capture_get,
    .capture_set = capture_set,
    .capture_close = capture_close,
};

}  // namespace
}  // namespace gvkit::detail

extern "C" __attribute__((visibility("default"))) const gvkit::detail::OpenCvMediaTable*
gvkit_opencv_media_table() {
  return &gvkit::detail::kTable;
}
