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

// The lossless compression of written EXR files (all read back to the same floats):
//   kZip   OpenEXR's ZIP (zlib over blocks of 16 scanlines): the smallest files, the slowest to
//          write;
//   kRle   run lengths: faster to write, larger files where values vary from pixel to pixel;
//   kNone  uncompressed: the fastest, the largest files.
// ZIP and ZIPS files of 32-bit float channels are read, and ZIP files written, chunk by chunk
// with libdeflate (core/src/exr_zip_chunk.hpp) around OpenEXR's file structure; other files go
// through OpenEXR's own decoding. A 320x320 geometry image (X, Y, Z, T, M) on one core
// (docs/benchmarks.md, "EXR ZIP chunks by libdeflate"): ZIP about 24-28 ms to write, 7-8 ms to
// read, 1.5 MB; RLE 8 / 10 ms, 1.8 MB; none 3 / 8 ms, 2.1 MB. The X, Y, Z, T, M channels of a
// 640x480 range scan with holes: ZIP 1.1 MB (13 ms to read), RLE 3.7 MB, none 5.3 MB.
enum class ExrCompression { kZip, kRle, kNone };
const char* exr_compression_name(ExrCompression compression);  // "zip", "rle", "none"
// Fails naming the text when it is none of the names.
Result<ExrCompression> parse_exr_compression(const std::string& name);

// Writes 32-bit float channels. Fails on empty input or mismatched sizes.
Status write_exr(const std::filesystem::path& path, const ExrChannels& channels,
                 ExrCompression compression = ExrCompression::kZip);
// Reads every channel as CV_32F. Fails with the file name on a missing, truncated or non-EXR file.
Result<ExrChannels> read_exr(const std::filesystem::path& path);

// RangeScan <-> EXR: X, Y, Z (mm, NaN invalid), T (texture), Q (quality), M (valid, 0 or 1).
Status write_range_scan_exr(const std::filesystem::path& path, const RangeScan& scan,
                            ExrCompression compression = ExrCompression::kZip);
Result<RangeScan> read_range_scan_exr(const std::filesystem::path& path);

// GeometryImage <-> EXR: X, Y, Z (mm), T (texture, only if present), M (domain mask, 0 or 1).
Status write_geometry_image_exr(const std::filesystem::path& path, const GeometryImage& image,
                                ExrCompression compression = ExrCompression::kZip);
Result<GeometryImage> read_geometry_image_exr(const std::filesystem::path& path);

}  // namespace gvkit
