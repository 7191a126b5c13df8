// OpenCV's codecs behind the plugin (opencv_media.hpp): not loaded before their first use, then
// the same images and videos as OpenCV gives; a missing or wrong plugin is a clear error. This
// binary links gvkit::core only, so what is mapped into it is what core loads.
#include "gvkit/core/opencv_media.hpp"

#include <dlfcn.h>
#include <link.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "gvkit/core/gl_driver_modules.hpp"
#include "gvkit/core/image_io.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;

// Whether a shared object whose path contains `part` is mapped into this process.
bool mapped(const std::string& part) {
  struct Search {
    std::string part;
    bool found = false;
  } search{part};
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* data) {
        auto* s = static_cast<Search*>(data);
        if (info->dlpi_name && std::string(info->dlpi_name).find(s->part) != std::string::npos)
          s->found = true;
        return 0;
      },
      &search);
  return search.found;
}

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("gvkit_opencv_media_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

cv::Mat pattern(int rows, int cols, int type) {
  cv::Mat m(rows, cols, type);
  cv::randu(m, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// First in this binary: nothing has used the codecs yet.
TEST(OpenCvMedia, CodecsAreLoadedOnFirstUseOnly) {
  EXPECT_FALSE(mapped("libopencv_imgcodecs"));
  EXPECT_FALSE(mapped("libopencv_videoio"));
  EXPECT_FALSE(mapped("libgvkit_opencv_media"));
  const fs::path dir = temp_dir("first_use");
  ASSERT_TRUE(write_image(dir / "a.png", pattern(8, 8, CV_8U)).is_ok());
  EXPECT_TRUE(mapped("libgvkit_opencv_media"));
  EXPECT_TRUE(mapped("libopencv_imgcodecs"));
  fs::remove_all(dir);
}

TEST(OpenCvMedia, ImagesRoundTripThroughFilesAndMemory) {
  const fs::path dir = temp_dir("images");
  for (int type : {CV_8UC1, CV_8UC3, CV_16UC1, CV_16UC3}) {
    const cv::Mat image = pattern(37, 53, type);
    const std::string path = (dir / "x.png").string();
    Result<bool> written = opencv_media::imwrite(path, image);
    ASSERT_TRUE(written.is_ok()) << written.status().message();
    EXPECT_TRUE(written.value());
    Result<cv::Mat> read = opencv_media::imread(path, cv::IMREAD_UNCHANGED);
    ASSERT_TRUE(read.is_ok());
    EXPECT_TRUE(same(*read, image)) << "type " << type;

    std::vector<uint8_t> bytes;
    Result<bool> encoded = opencv_media::imencode(".png", image, &bytes);
    ASSERT_TRUE(encoded.is_ok() && encoded.value());
    Result<cv::Mat> decoded = opencv_media::imdecode(
        cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()), cv::IMREAD_UNCHANGED);
    ASSERT_TRUE(decoded.is_ok());
    EXPECT_TRUE(same(*decoded, image)) << "type " << type;
  }
  // Data OpenCV cannot decode: an empty picture, as cv::imread gives.
  std::ofstream(dir / "bad.png") << "not a png";
  Result<cv::Mat> bad = opencv_media::imread((dir / "bad.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_TRUE(bad.is_ok());
  EXPECT_TRUE(bad->empty());
  // An extension without an encoder: false, nothing written.
  Result<bool> unknown = opencv_media::imwrite((dir / "x.unknown_ext").string(), pattern(4, 4, 0));
  EXPECT_TRUE(!unknown.is_ok() || !unknown.value());
  EXPECT_FALSE(fs::exists(dir / "x.unknown_ext"));
  fs::remove_all(dir);
}

TEST(OpenCvMedia, VideoWrittenAndReadBack) {
  const fs::path dir = temp_dir("video");
  const std::string path = (dir / "v.avi").string();
  {
    opencv_media::VideoWriter writer;
    // FFV1 is lossless: the grey levels come back exactly.
    ASSERT_TRUE(
        writer.open(path, cv::CAP_FFMPEG, opencv_media::fourcc('F', 'F', 'V', '1'), 25, {64, 48})
            .is_ok());
    ASSERT_TRUE(writer.is_open());
    for (int k = 0; k < 5; ++k)
      ASSERT_TRUE(writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(40 * k + 10))).is_ok());
    writer.release();
    EXPECT_FALSE(writer.is_open());
  }
  opencv_media::VideoCapture capture;
  ASSERT_TRUE(capture.open(path, cv::CAP_FFMPEG).is_ok());
  EXPECT_EQ(capture.get(cv::CAP_PROP_FRAME_WIDTH), 64);
  EXPECT_EQ(capture.get(cv::CAP_PROP_FRAME_HEIGHT), 48);
  cv::Mat picture;
  int frames = 0;
  for (;;) {
    Result<bool> read = capture.read(&picture);
    ASSERT_TRUE(read.is_ok());
    if (!read.value()) break;
    ASSERT_EQ(picture.size(), cv::Size(64, 48));
    EXPECT_EQ(picture.at<cv::Vec3b>(20, 30)[1], 40 * frames + 10);
    ++frames;
  }
  EXPECT_EQ(frames, 5);
  // A file that is not a video: an error naming it.
  std::ofstream(dir / "not_video.mp4") << "text";
  opencv_media::VideoCapture other;
  const Status status = other.open((dir / "not_video.mp4").string(), cv::CAP_FFMPEG);
  EXPECT_EQ(status.code(), StatusCode::kUnsupported);
  EXPECT_NE(status.message().find("not_video.mp4"), std::string::npos);
  // A writer that cannot open its file: an I/O error naming it.
  opencv_media::VideoWriter nowhere;
  const std::string missing = (dir / "missing_dir" / "v.avi").string();
  const Status refused =
      nowhere.open(missing, cv::CAP_FFMPEG, opencv_media::fourcc('F', 'F', 'V', '1'), 25, {64, 48});
  EXPECT_FALSE(refused.is_ok());
  EXPECT_NE(refused.message().find("missing_dir"), std::string::npos);
  fs::remove_all(dir);
}

// The plugin loads while another thread pins the GL driver's modules (as the player window
// does when it opens): pin_gl_driver_modules once called dlopen from inside dl_iterate_phdr,
// which deadlocked against this dlopen. Needs Mesa's GLX module (skipped without it).
TEST(OpenCvMedia, LoadsWhileGlDriverModulesArePinned) {
  if (!dlopen("libGLX_mesa.so.0", RTLD_NOW)) GTEST_SKIP() << "no libGLX_mesa.so.0";
  std::atomic<bool> loaded{false};
  std::thread pinning([&] {
    while (!loaded) pin_gl_driver_modules();
  });
  std::future<Status> load = std::async(std::launch::async, [] { return opencv_media::load(); });
  if (load.wait_for(std::chrono::seconds(120)) != std::future_status::ready) {
    std::fprintf(stderr, "the plugin's load did not finish in 120 s (a deadlock)\n");
    std::_Exit(1);
  }
  loaded = true;
  pinning.join();
  EXPECT_TRUE(load.get().is_ok());
}

TEST(OpenCvMedia, AWrongPluginIsRefusedNamingIt) {
  EXPECT_TRUE(opencv_media::load().is_ok());
  const Status missing = opencv_media::check_plugin("/nonexistent/libgvkit_opencv_media.so");
  EXPECT_EQ(missing.code(), StatusCode::kUnsupported);
  EXPECT_NE(missing.message().find("/nonexistent/libgvkit_opencv_media.so"), std::string::npos);
  // A shared object that is not the plugin.
  const Status other = opencv_media::check_plugin("libz.so.1");
  EXPECT_EQ(other.code(), StatusCode::kUnsupported);
  EXPECT_NE(other.message().find("not a gvkit OpenCV media plugin"), std::string::npos);
}

}  // namespace
}  // namespace gvkit
