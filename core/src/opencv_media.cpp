#include "gvkit/core/opencv_media.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "opencv_media_table.hpp"

// Where the plugin is looked for (core/CMakeLists.txt): relative to the folder of the running
// executable as installed, where this build writes it, where `cmake --install` puts it.
#ifndef GVKIT_OPENCV_MEDIA_FROM_BIN
#define GVKIT_OPENCV_MEDIA_FROM_BIN ""
#endif
#ifndef GVKIT_OPENCV_MEDIA_BUILT
#define GVKIT_OPENCV_MEDIA_BUILT ""
#endif
#ifndef GVKIT_OPENCV_MEDIA_INSTALLED
#define GVKIT_OPENCV_MEDIA_INSTALLED ""
#endif

namespace gvkit::opencv_media {
namespace {

using detail::OpenCvMediaTable;

// The table of the plugin at `path`, loaded and kept (a plugin is never closed), or why not.
Result<const OpenCvMediaTable*> open_table(const std::string& path) {
  void* library = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
  if (!library) {
    const char* why = dlerror();
    const std::string message = why ? why : "cannot be loaded";
    // dlerror's text usually starts with the path already.
    return unsupported(message.find(path) == std::string::npos ? path + ": " + message : message);
  }
  using Entry = const OpenCvMediaTable* (*)();
  auto entry = reinterpret_cast<Entry>(dlsym(library, "gvkit_opencv_media_table"));
  const OpenCvMediaTable* table = entry ? entry() : nullptr;
  if (!table) {
    dlclose(library);
    return unsupported(path + ": not a gvkit OpenCV media plugin");
  }
  if (table->abi != detail::kOpenCvMediaAbi || table->size != sizeof(OpenCvMediaTable)) {
    const std::string versions =
        std::to_string(table->abi) + ", this build's " + std::to_string(detail::kOpenCvMediaAbi);
    dlclose(library);
    return unsupported(path + ": a plugin of another gvkit build (table version " + versions + ")");
  }
  return table;
}

struct Plugin {
  const OpenCvMediaTable* table = nullptr;
  Status status;
};

Plugin find_plugin() {
  std::vector<std::string> paths;
  const char* chosen = std::getenv("GVKIT_OPENCV_MEDIA");
  if (chosen && *chosen) {
    paths.emplace_back(chosen);
  } else {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec && *GVKIT_OPENCV_MEDIA_FROM_BIN)
      paths.push_back(
          (exe.parent_path() / GVKIT_OPENCV_MEDIA_FROM_BIN).lexically_normal().string());
    for (const char* path : {GVKIT_OPENCV_MEDIA_BUILT, GVKIT_OPENCV_MEDIA_INSTALLED})
      if (*path && std::find(paths.begin(), paths.end(), path) == paths.end())
        paths.emplace_back(path);
  }
  std::string tried;
  for (const std::string& path : paths) {
    Result<const OpenCvMediaTable*> table = open_table(path);
    if (table.is_ok()) return {table.value(), Status::ok()};
    tried += (tried.empty() ? "" : "; ") + table.status().message();
  }
  return {nullptr, unsupported("OpenCV's image and video codecs are not available: the plugin "
                               "libgvkit_opencv_media.so did not load (" +
                               (tried.empty() ? std::string("no path known") : tried) +
                               "); set GVKIT_OPENCV_MEDIA to its path")};
}

const Plugin& plugin() {
  static const Plugin found = find_plugin();
  return found;
}

// The table, or the reason it is missing.
Result<const OpenCvMediaTable*> table() {
  const Plugin& p = plugin();
  if (!p.table) return p.status;
  return p.table;
}

}  // namespace

Status load() { return plugin().status; }

Status check_plugin(const std::string& path) { return open_table(path).status(); }

Result<cv::Mat> imread(const std::string& path, int flags) {
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  cv::Mat image;
  std::string error;
  if (!t->imread(path, flags, &image, &error))
    return corrupt_data(path + ": cannot decode image: " + error);
  return image;
}

Result<cv::Mat> imdecode(const cv::Mat& data, int flags) {
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  cv::Mat image;
  std::string error;
  if (!t->imdecode(data, flags, &image, &error))
    return corrupt_data("cannot decode image: " + error);
  return image;
}

Result<bool> imwrite(const std::string& path, const cv::Mat& image,
                     const std::vector<int>& params) {
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  bool done = false;
  std::string error;
  if (!t->imwrite(path, image, params, &done, &error))
    return io_error(path + ": cannot write image: " + error);
  return done;
}

Result<bool> imencode(const std::string& extension, const cv::Mat& image, std::vector<uint8_t>* out,
                      const std::vector<int>& params) {
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  bool done = false;
  std::string error;
  if (!t->imencode(extension, image, params, out, &done, &error))
    return io_error("cannot encode " + extension + " image: " + error);
  return done;
}

VideoWriter& VideoWriter::operator=(VideoWriter&& other) noexcept {
  if (this != &other) {
    release();
    handle_ = other.handle_;
    other.handle_ = nullptr;
  }
  return *this;
}

Status VideoWriter::open(const std::string& path, int api, int fourcc_code, double fps,
                         cv::Size size) {
  release();
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  std::string error;
  handle_ = t->writer_open(path, api, fourcc_code, fps, size.width, size.height, &error);
  if (!handle_)
    return io_error(path + ": cannot open a video writer" + (error.empty() ? "" : ": " + error));
  return Status::ok();
}

Status VideoWriter::write(const cv::Mat& picture) {
  GVKIT_CHECK(handle_, "write() on an open video writer");
  std::string error;
  if (!plugin().table->writer_write(handle_, picture, &error))
    return io_error("cannot write a video picture: " + error);
  return Status::ok();
}

void VideoWriter::release() {
  if (handle_) plugin().table->writer_close(handle_);
  handle_ = nullptr;
}

VideoCapture& VideoCapture::operator=(VideoCapture&& other) noexcept {
  if (this != &other) {
    release();
    handle_ = other.handle_;
    other.handle_ = nullptr;
  }
  return *this;
}

Status VideoCapture::open(const std::string& path, int api) {
  release();
  GVKIT_ASSIGN_OR_RETURN(const OpenCvMediaTable* t, table());
  std::string error;
  handle_ = t->capture_open(path, api, &error);
  if (!handle_)
    return unsupported(path + ": not a video that OpenCV/FFmpeg can open" +
                       (error.empty() ? "" : ": " + error));
  return Status::ok();
}

Result<bool> VideoCapture::read(cv::Mat* picture) {
  GVKIT_CHECK(handle_, "read() on an open video capture");
  std::string error;
  if (plugin().table->capture_read(handle_, picture, &error)) return !picture->empty();
  if (!error.empty()) return io_error("cannot read a video picture: " + error);
  return false;
}

double VideoCapture::get(int property) const {
  return handle_ ? plugin().table->capture_get(handle_, property) : 0.0;
}

bool VideoCapture::set(int property, double value) {
  return handle_ && plugin().table->capture_set(handle_, property, value);
}

void VideoCapture::release() {
  if (handle_) plugin().table->capture_close(handle_);
  handle_ = nullptr;
}

}  // namespace gvkit::opencv_media
