#pragma once
// OpenCV's image and video codecs (imgcodecs: PNG, TIFF, JPEG...; videoio: MP4 and other video
// files through FFmpeg), loaded on first use from a plugin, libgvkit_opencv_media.so (dlopen).
// Linked into the program, those two modules bring some 250 shared libraries (GDAL, FFmpeg's
// codecs, GStreamer...) whose loading took most of every gvkit command's start (0.16 of 0.18 s,
// docs/benchmarks.md "Commands start without OpenCV's codecs"), for commands that never read an
// image as well.
//
// The plugin is looked for at $GVKIT_OPENCV_MEDIA when that is set (and only there), else at
// <bindir>/../<libdir>/gvkit/ from the running executable's folder (an installed gvkit, at any
// prefix), where this build wrote it, where `cmake --install` puts it. When it does not
// load, every function here returns an unsupported error that names the paths tried and why
// each failed; the first use decides, for the whole process. Thread-safe.

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit::opencv_media {

// Loads the plugin now (it is otherwise loaded by the first call below). Ok when it is usable.
Status load();
// Tries to load the plugin at `path`, without keeping it as the one in use: ok when it is a
// plugin of this build, else an error that names `path` (for tests and diagnostics).
Status check_plugin(const std::string& path);

// cv::imread(path, flags) (cv::ImreadModes): an empty Mat when OpenCV cannot decode the file, an
// error when OpenCV threw or the plugin is missing.
Result<cv::Mat> imread(const std::string& path, int flags);
// cv::imdecode of encoded bytes (a 1-row CV_8U Mat): empty when they do not decode.
Result<cv::Mat> imdecode(const cv::Mat& data, int flags);
// cv::imwrite: false when OpenCV wrote nothing (no encoder for the extension, or it failed).
Result<bool> imwrite(const std::string& path, const cv::Mat& image,
                     const std::vector<int>& params = {});
// cv::imencode into *out (extension with its dot, ".png"): false when OpenCV could not encode.
Result<bool> imencode(const std::string& extension, const cv::Mat& image, std::vector<uint8_t>* out,
                      const std::vector<int>& params = {});

// cv::VideoWriter::fourcc, without the module.
constexpr int fourcc(char c1, char c2, char c3, char c4) {
  return (c1 & 255) | ((c2 & 255) << 8) | ((c3 & 255) << 16) | ((c4 & 255) << 24);
}

// A cv::VideoWriter in the plugin. Move-only; released by release() or the destructor.
class VideoWriter {
 public:
  VideoWriter() = default;
  ~VideoWriter() { release(); }
  VideoWriter(VideoWriter&& other) noexcept : handle_(other.handle_) { other.handle_ = nullptr; }
  VideoWriter& operator=(VideoWriter&& other) noexcept;
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // cv::VideoWriter::open(path, api (cv::VideoCaptureAPIs), fourcc, fps, size), colour
  // pictures. An I/O error naming `path` when no writer opens (a writer already open is released
  // first).
  Status open(const std::string& path, int api, int fourcc, double fps, cv::Size size);
  bool is_open() const { return handle_ != nullptr; }
  // Appends a picture of the opened size (8-bit BGR). Precondition: is_open().
  Status write(const cv::Mat& picture);
  // Finishes the file (the container's index); nothing when not open.
  void release();

 private:
  void* handle_ = nullptr;
};

// A cv::VideoCapture in the plugin, reading a video file. Move-only.
class VideoCapture {
 public:
  VideoCapture() = default;
  ~VideoCapture() { release(); }
  VideoCapture(VideoCapture&& other) noexcept : handle_(other.handle_) { other.handle_ = nullptr; }
  VideoCapture& operator=(VideoCapture&& other) noexcept;
  VideoCapture(const VideoCapture&) = delete;
  VideoCapture& operator=(const VideoCapture&) = delete;

  // cv::VideoCapture::open(path, api). Unsupported (naming `path`) when it does not open.
  Status open(const std::string& path, int api);
  bool is_open() const { return handle_ != nullptr; }
  // The next picture into *picture: true, or false at the end of the file (or when the backend
  // gives none); an error when OpenCV threw. Precondition: is_open().
  Result<bool> read(cv::Mat* picture);
  // cv::VideoCapture::get / set (cv::VideoCaptureProperties); 0 / false when not open.
  double get(int property) const;
  bool set(int property, double value);
  void release();

 private:
  void* handle_ = nullptr;
};

}  // namespace gvkit::opencv_media
