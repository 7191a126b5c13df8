#pragma once
// The function table of the OpenCV media plugin (libgvkit_opencv_media.so, built from
// opencv_media_plugin.cpp), which opencv_media.cpp loads with dlopen. Private to core: both sides
// are built together, and kOpenCvMediaAbi changes with every change of this table, so that a
// plugin of another build is refused rather than called wrongly.
//
// No exception crosses the table: what OpenCV throws comes back as false and a message.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace gvkit::detail {

inline constexpr int kOpenCvMediaAbi = 1;

struct OpenCvMediaTable {
  int abi;      // kOpenCvMediaAbi of the plugin's build
  size_t size;  // sizeof(OpenCvMediaTable) there

  // cv::imread / cv::imdecode: `out` empty for data OpenCV cannot decode. False when it threw.
  bool (*imread)(const std::string& path, int flags, cv::Mat* out, std::string* error);
  bool (*imdecode)(const cv::Mat& data, int flags, cv::Mat* out, std::string* error);
  // cv::imwrite / cv::imencode: *done is what OpenCV returned. False when it threw.
  bool (*imwrite)(const std::string& path, const cv::Mat& image, const std::vector<int>& params,
                  bool* done, std::string* error);
  bool (*imencode)(const std::string& extension, const cv::Mat& image,
                   const std::vector<int>& params, std::vector<uint8_t>* out, bool* done,
                   std::string* error);

  // cv::VideoWriter: a handle, null when no writer opens (`error` then says why, if OpenCV
  // threw). write returns false when OpenCV threw.
  void* (*writer_open)(const std::string& path, int api, int fourcc, double fps, int width,
                       int height, std::string* error);
  bool (*writer_write)(void* writer, const cv::Mat& picture, std::string* error);
  void (*writer_close)(void* writer);

  // cv::VideoCapture: a handle, null when the file does not open. read returns false at the end
  // or on a failure (`error` set when OpenCV threw).
  void* (*capture_open)(const std::string& path, int api, std::string* error);
  bool (*capture_read)(void* capture, cv::Mat* picture, std::string* error);
  double (*capture_get)(void* capture, int property);
  bool (*capture_set)(void* capture, int property, double value);
  void (*capture_close)(void* capture);
};

}  // namespace gvkit::detail

// The plugin's one exported symbol.
extern "C" const gvkit::detail::OpenCvMediaTable* gvkit_opencv_media_table();
