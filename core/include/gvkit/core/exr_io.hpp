#pragma once
// OpenEXR I/O of float images with named channels, and of the two per-frame EXR files of gvkit:
// RangeScan (channels X, Y, Z, T, Q, M) and GeometryImage (X, Y, Z, [T], M). Writes are atomic
// (temporary file + rename): a failed write leaves no partial file behind.

#include <filesystem>
#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

// Channel name -> CV_32F plane. All planes share one size.
using ExrChannels = std::map<std::string, cv::Mat>;

// Writes 32-bit float channels (ZIP compression). Fails on empty input or mismatched sizes.
Status write_exr(const std::filesystem::path& path, const ExrChannels& channels);
// Reads every channel as CV_32F. Fails with the file name on a missing, truncated or non-EXR file.
Result<ExrChannels> read_exr(const std::filesystem::path& path);

// RangeScan <-> EXR: X, Y, Z (mm, NaN invalid), T (texture), Q (quality), M (valid, 0 or 1).
Status write_range_scan_exr(const std::filesystem::path& path, const RangeScan& scan);
Result<RangeScan> read_range_scan_exr(const std::filesystem::path& path);

// GeometryImage <-> EXR: X, Y, Z (mm), T (texture, only if present), M (domain mask, 0 or 1).
Status write_geometry_image_exr(const std::filesystem::path& path, const GeometryImage& image);
Result<GeometryImage> read_geometry_image_exr(const std::filesystem::path& path);

}  // namespace gvkit
