#include "gvkit/core/exr_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfVersion.h>
#include <openexr.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "exr_zip_chunk.hpp"
#include "gvkit/core/atomic_file.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

// Splits xyz into X, Y, Z planes and adds them to channels.
void add_xyz(const cv::Mat& xyz, ExrChannels& channels) {
  std::vector<cv::Mat> planes;
  cv::split(xyz, planes);
  channels["X"] = planes[0];
  channels["Y"] = planes[1];
  channels["Z"] = planes[2];
}

Result<cv::Mat> take(const ExrChannels& channels, const std::string& name, const fs::path& path) {
  auto it = channels.find(name);
  if (it == channels.end()) return corrupt_data(path.string() + ": missing channel " + name);
  return it->second;
}

Result<cv::Mat> merge_xyz(const ExrChannels& channels, const fs::path& path) {
  GVKIT_ASSIGN_OR_RETURN(cv::Mat x, take(channels, "X", path));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat y, take(channels, "Y", path));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat z, take(channels, "Z", path));
  cv::Mat xyz;
  cv::merge(std::vector<cv::Mat>{x, y, z}, xyz);
  return xyz;
}

cv::Mat mask_from_channel(const cv::Mat& m) {
  cv::Mat mask;
  cv::compare(m, 0.5, mask, cv::CMP_GT);  // 255 where > 0.5; NaN compares false
  return mask;
}

cv::Mat channel_from_mask(const cv::Mat& mask) {
  cv::Mat m;
  mask.convertTo(m, CV_32F, 1.0 / 255.0);
  return m;
}

Imf::Compression openexr_compression(ExrCompression compression) {
  switch (compression) {
    case ExrCompression::kRle:
      return Imf::RLE_COMPRESSION;
    case ExrCompression::kNone:
      return Imf::NO_COMPRESSION;
    case ExrCompression::kZip:
      break;
  }
  return Imf::ZIP_COMPRESSION;
}

// Scanlines per chunk of OpenEXR's ZIP compression (ZIPS: one).
constexpr int kZipChunkLines = 16;

// Whether the pixels of a single-part file are chunks that read_zip_chunks decodes: scanlines
// (not tiles) in ZIP or ZIPS compression, every channel 32-bit float and unsampled, on a
// little-endian machine (as EXR stores floats).
bool zip_float_channels(const Imf::Header& header) {
  if (std::endian::native != std::endian::little || header.hasTileDescription() ||
      (header.hasType() && header.type() != Imf::SCANLINEIMAGE))
    return false;
  if (header.compression() != Imf::ZIP_COMPRESSION && header.compression() != Imf::ZIPS_COMPRESSION)
    return false;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
    if (it.channel().type != Imf::FLOAT || it.channel().xSampling != 1 ||
        it.channel().ySampling != 1)
      return false;
  return true;
}

// The pixels of a file that zip_float_channels accepts, chunk by chunk: the stored chunk as
// OpenEXR reads it (rawPixelData: the offset table, the chunk's header), decoded by
// ExrZipChunkCoder, and its lines (each channel's row of floats in the channel list's order)
// copied into the planes.
Status read_zip_chunks(Imf::InputFile& file, ExrChannels& planes, const fs::path& path) {
  const Imath::Box2i window = file.header().dataWindow();
  const int width = window.max.x - window.min.x + 1;
  const int lines = file.header().compression() == Imf::ZIP_COMPRESSION ? kZipChunkLines : 1;
  std::vector<cv::Mat*> order;  // planes in the file's channel order
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
    order.push_back(&planes.at(it.name()));
  const size_t row_bytes = static_cast<size_t>(width) * sizeof(float);
  const size_t line_bytes = row_bytes * order.size();
  std::vector<uint8_t> chunk(line_bytes * lines);
  detail::ExrZipChunkCoder coder;
  for (int y0 = window.min.y; y0 <= window.max.y; y0 += lines) {
    const int n = std::min(lines, window.max.y - y0 + 1);
    const char* packed = nullptr;
    int packed_size = 0;
    file.rawPixelData(y0, packed, packed_size);
    if (packed_size < 0 ||
        !coder.unpack(reinterpret_cast<const uint8_t*>(packed), static_cast<size_t>(packed_size),
                      chunk.data(), line_bytes * n))
      return corrupt_data(path.string() + ": EXR chunk at line " + std::to_string(y0) +
                          " does not decompress to its size");
    const uint8_t* from = chunk.data();
    for (int y = y0 - window.min.y; y < y0 - window.min.y + n; ++y)
      for (cv::Mat* plane : order) {
        std::memcpy(plane->ptr(y), from, row_bytes);
        from += row_bytes;
      }
  }
  return Status::ok();
}

// The last message of OpenEXR's C API on this thread (its contexts report errors through a
// callback).
thread_local std::string exr_core_message;

// A write context of OpenEXR's C API, finished (and its file closed) when it goes out of scope.
struct ExrWriteContext {
  exr_context_t context = nullptr;
  ~ExrWriteContext() {
    if (context) exr_finish(&context);
  }
};

// Writes the planes (CV_32F, one size) to file as a ZIP-compressed scanline EXR through OpenEXR's
// C API (the header, the chunk offset table), each chunk of 16 lines packed by ExrZipChunkCoder:
// the same file layout as Imf::OutputFile writes, with libdeflate's zlib streams. Errors name
// path.
Status write_zip_chunks(const fs::path& file, const ExrChannels& planes, const fs::path& path) {
  const cv::Size size = planes.begin()->second.size();
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = [](exr_const_context_t, exr_result_t, const char* message) {
    exr_core_message = message ? message : "";
  };
  exr_core_message.clear();
  const auto failed = [&](exr_result_t code) {
    return io_error(
        path.string() + ": cannot write EXR: " +
        (exr_core_message.empty() ? exr_get_default_error_message(code) : exr_core_message));
  };
  ExrWriteContext out;
  exr_result_t r = exr_start_write(&out.context, file.c_str(), EXR_WRITE_FILE_DIRECTLY, &init);
  int part = 0;
  if (r != EXR_ERR_SUCCESS ||
      (r = exr_add_part(out.context, nullptr, EXR_STORAGE_SCANLINE, &part)) != EXR_ERR_SUCCESS ||
      (r = exr_initialize_required_attr_simple(out.context, part, size.width, size.height,
                                               EXR_COMPRESSION_ZIP)) != EXR_ERR_SUCCESS)
    return failed(r);
  for (const auto& [name, plane] : planes)
    if ((r = exr_add_channel(out.context, part, name.c_str(), EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1)) != EXR_ERR_SUCCESS)
      return failed(r);
  // The lines hold the channels in the file's channel list order (sorted by name).
  const exr_attr_chlist_t* list = nullptr;
  if ((r = exr_write_header(out.context)) != EXR_ERR_SUCCESS ||
      (r = exr_get_channels(out.context, part, &list)) != EXR_ERR_SUCCESS)
    return failed(r);
  std::vector<const cv::Mat*> order;
  for (int c = 0; c < list->num_channels; ++c)
    order.push_back(
        &planes.at(std::string(list->entries[c].name.str, list->entries[c].name.length)));
  const size_t row_bytes = static_cast<size_t>(size.width) * sizeof(float);
  const size_t line_bytes = row_bytes * order.size();
  std::vector<uint8_t> chunk(line_bytes * kZipChunkLines);
  detail::ExrZipChunkCoder coder;
  for (int y0 = 0; y0 < size.height; y0 += kZipChunkLines) {
    const int n = std::min(kZipChunkLines, size.height - y0);
    uint8_t* to = chunk.data();
    for (int y = y0; y < y0 + n; ++y)
      for (const cv::Mat* plane : order) {
        std::memcpy(to, plane->ptr(y), row_bytes);
        to += row_bytes;
      }
    const std::vector<uint8_t>& packed = coder.pack(chunk.data(), line_bytes * n);
    if ((r = exr_write_scanline_chunk(out.context, part, y0, packed.data(), packed.size())) !=
        EXR_ERR_SUCCESS)
      return failed(r);
  }
  // The chunk offset table is written here.
  r = exr_finish(&out.context);
  out.context = nullptr;
  return r == EXR_ERR_SUCCESS ? Status::ok() : failed(r);
}

constexpr ExrCompression kExrCompressions[] = {ExrCompression::kZip, ExrCompression::kRle,
                                               ExrCompression::kNone};

}  // namespace

const char* exr_compression_name(ExrCompression compression) {
  switch (compression) {
    case ExrCompression::kRle:
      return "rle";
    case ExrCompression::kNone:
      return "none";
    case ExrCompression::kZip:
      break;
  }
  return "zip";
}

Result<ExrCompression> parse_exr_compression(const std::string& name) {
  for (const ExrCompression c : kExrCompressions)
    if (name == exr_compression_name(c)) return c;
  return invalid_argument("EXR compression '" + name + "': expected zip, rle or none");
}

Status write_exr(const fs::path& path, const ExrChannels& channels, ExrCompression compression) {
  if (channels.empty()) return invalid_argument(path.string() + ": no channels to write");
  const cv::Size size = channels.begin()->second.size();
  if (size.area() == 0) return invalid_argument(path.string() + ": empty image");
  for (const auto& [name, plane] : channels) {
    if (plane.type() != CV_32F || plane.size() != size)
      return invalid_argument(path.string() + ": channel " + name +
                              " must be CV_32F and the size of the others");
  }
  return write_via_temp_file(path, [&](const fs::path& temp) -> Status {
    try {
      if (compression == ExrCompression::kZip && std::endian::native == std::endian::little)
        return write_zip_chunks(temp, channels, path);
      Imf::Header header(size.width, size.height);
      header.compression() = openexr_compression(compression);
      Imf::FrameBuffer frame_buffer;
      std::vector<cv::Mat> keep;
      for (const auto& [name, plane] : channels) {
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        cv::Mat c = plane.isContinuous() ? plane : plane.clone();
        keep.push_back(c);
        frame_buffer.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(c.data),
                                             sizeof(float), c.step[0]));
      }
      Imf::OutputFile file(temp.c_str(), header);
      file.setFrameBuffer(frame_buffer);
      file.writePixels(size.height);
    } catch (const std::exception& e) {
      return io_error(path.string() + ": cannot write EXR: " + e.what());
    }
    return Status::ok();
  });
}

Result<ExrChannels> read_exr(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const int width = window.max.x - window.min.x + 1;
    const int height = window.max.y - window.min.y + 1;
    if (width <= 0 || height <= 0 || static_cast<int64_t>(width) * height > (1LL << 28))
      return corrupt_data(path.string() + ": implausible data window");
    // Chunk by chunk every sample is written; OpenEXR's decoding (into a frame buffer over the
    // planes) leaves NaN where it writes none.
    const bool by_chunks = !Imf::isMultiPart(file.version()) && zip_float_channels(file.header());
    ExrChannels channels;
    Imf::FrameBuffer frame_buffer;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        return unsupported(path.string() + ": subsampled channel " + it.name());
      cv::Mat& plane = channels[it.name()];
      plane.create(height, width, CV_32F);
      if (by_chunks) continue;
      plane.setTo(std::numeric_limits<float>::quiet_NaN());
      char* origin = reinterpret_cast<char*>(plane.data) -
                     (static_cast<ptrdiff_t>(window.min.x) * sizeof(float) +
                      static_cast<ptrdiff_t>(window.min.y) * plane.step[0]);
      frame_buffer.insert(it.name(), Imf::Slice(Imf::FLOAT, origin, sizeof(float), plane.step[0]));
    }
    if (channels.empty()) return corrupt_data(path.string() + ": EXR has no channels");
    if (!file.isComplete()) return corrupt_data(path.string() + ": EXR is truncated");
    if (by_chunks) {
      GVKIT_RETURN_IF_ERROR(read_zip_chunks(file, channels, path));
    } else {
      file.setFrameBuffer(frame_buffer);
      file.readPixels(window.min.y, window.max.y);
    }
    return channels;
  } catch (const std::exception& e) {
    return corrupt_data(path.string() + ": not a readable EXR: " + e.what());
  }
}

Status write_range_scan_exr(const fs::path& path, const RangeScan& scan,
                            ExrCompression compression) {
  GVKIT_RETURN_IF_ERROR(scan.check().with_context(path.string()));
  ExrChannels channels;
  add_xyz(scan.xyz_mm, channels);
  channels["T"] = scan.texture.empty() ? cv::Mat(scan.size(), CV_32F, cv::Scalar(0)) : scan.texture;
  channels["Q"] = scan.quality.empty() ? cv::Mat(scan.size(), CV_32F, cv::Scalar(0)) : scan.quality;
  channels["M"] = channel_from_mask(scan.valid);
  return write_exr(path, channels, compression);
}

Result<RangeScan> read_range_scan_exr(const fs::path& path) {
  GVKIT_ASSIGN_OR_RETURN(ExrChannels channels, read_exr(path));
  RangeScan scan;
  GVKIT_ASSIGN_OR_RETURN(scan.xyz_mm, merge_xyz(channels, path));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat m, take(channels, "M", path));
  scan.valid = mask_from_channel(m);
  if (channels.count("T")) scan.texture = channels["T"];
  if (channels.count("Q")) scan.quality = channels["Q"];
  GVKIT_RETURN_IF_ERROR(scan.check().with_context(path.string()));
  return scan;
}

Status write_geometry_image_exr(const fs::path& path, const GeometryImage& image,
                                ExrCompression compression) {
  GVKIT_RETURN_IF_ERROR(image.check().with_context(path.string()));
  ExrChannels channels;
  add_xyz(image.xyz_mm, channels);
  if (!image.texture.empty()) channels["T"] = image.texture;
  channels["M"] = channel_from_mask(image.domain_mask);
  return write_exr(path, channels, compression);
}

Result<GeometryImage> read_geometry_image_exr(const fs::path& path) {
  GVKIT_ASSIGN_OR_RETURN(ExrChannels channels, read_exr(path));
  GeometryImage image;
  GVKIT_ASSIGN_OR_RETURN(image.xyz_mm, merge_xyz(channels, path));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat m, take(channels, "M", path));
  image.domain_mask = mask_from_channel(m);
  if (channels.count("T")) image.texture = channels["T"];
  GVKIT_RETURN_IF_ERROR(image.check().with_context(path.string()));
  return image;
}

}  // namespace gvkit
