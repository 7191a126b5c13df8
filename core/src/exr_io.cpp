#include "gvkit/core/exr_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <exception>
#include <limits>

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
  std::vector<cv::Mat> continuous;
  for (const auto& [name, plane] : channels) {
    if (plane.type() != CV_32F || plane.size() != size)
      return invalid_argument(path.string() + ": channel " + name +
                              " must be CV_32F and the size of the others");
  }
  return write_via_temp_file(path, [&](const fs::path& temp) -> Status {
    try {
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
    ExrChannels channels;
    Imf::FrameBuffer frame_buffer;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        return unsupported(path.string() + ": subsampled channel " + it.name());
      cv::Mat plane(height, width, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
      char* origin = reinterpret_cast<char*>(plane.data) -
                     (static_cast<ptrdiff_t>(window.min.x) * sizeof(float) +
                      static_cast<ptrdiff_t>(window.min.y) * plane.step[0]);
      frame_buffer.insert(it.name(), Imf::Slice(Imf::FLOAT, origin, sizeof(float), plane.step[0]));
      channels[it.name()] = plane;
    }
    if (channels.empty()) return corrupt_data(path.string() + ": EXR has no channels");
    file.setFrameBuffer(frame_buffer);
    if (!file.isComplete()) return corrupt_data(path.string() + ": EXR is truncated");
    file.readPixels(window.min.y, window.max.y);
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
