#pragma once
// 8/16-bit PNG (and any format OpenCV's imgcodecs reads, through opencv_media.hpp's plugin) with
// Status errors naming the file.

#include <filesystem>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit {

enum class ImageDepth { kAny, k8, k16 };

// Reads an image unchanged (8- or 16-bit, grey or colour). With kGrey it converts colour to grey.
// Fails on a missing or undecodable file, or when depth is given and does not match.
Result<cv::Mat> read_image(const std::filesystem::path& path, bool grey = false,
                           ImageDepth depth = ImageDepth::kAny);
// Writes CV_8U/CV_16U (1, 3 or 4 channels) losslessly, atomically (temp file + rename).
Status write_image(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace gvkit
