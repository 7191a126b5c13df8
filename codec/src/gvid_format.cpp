#include "gvkit/codec/gvid_format.hpp"

#include <cmath>
#include <cstring>

#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/crc8.hpp"

namespace gvkit::codec::format {
namespace {

constexpr size_t kFixedHeaderSize = 84;  // up to and including mask_bytes

bool magic_is(std::string_view bytes, const char (&magic)[4]) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), magic, 4) == 0;
}

}  // namespace

const char* frame_type_name(FrameType type) {
  switch (type) {
    case FrameType::kIntra:
      return "I";
    case FrameType::kPredicted:
      return "P";
    case FrameType::kBidirectional:
      return "B";
  }
  return "?";
}

std::string StreamFormat::description() const {
  std::string version = std::to_string(major) + "." + std::to_string(minor);
  if (legacy()) return version + " (legacy, read-only)";
  return version + ", profile " + profile_name(profile);
}

std::string write_file_header(const SequenceInfo& info, Profile profile) {
  GVKIT_CHECK(profile != Profile::kAuto, "a stream's profile is resolved before it is written");
  const std::string mask = encode_mask(info.domain_mask);
  ByteWriter w;
  w.bytes(std::string_view(kFileMagic, 4));
  w.u8(kMajorVersion);
  w.u8(kMinorVersion);
  w.u8(static_cast<uint8_t>(profile));  // profile_idc
  w.u8(0);
  w.u32(static_cast<uint32_t>(kFixedHeaderSize + mask.size() + 4));
  w.u32(static_cast<uint32_t>(info.width));
  w.u32(static_cast<uint32_t>(info.height));
  w.u8(static_cast<uint8_t>(info.bit_depth));
  w.u8(kPlaneX | kPlaneY | kPlaneZ | (info.has_texture ? kPlaneTexture : 0));
  w.u16(0);
  w.f64(info.fps);
  for (int a = 0; a < 3; ++a) w.f64(info.box_min_mm[a]);
  for (int a = 0; a < 3; ++a) w.f64(info.box_max_mm[a]);
  w.u32(static_cast<uint32_t>(mask.size()));
  w.bytes(mask);
  w.u32(crc32(w.str()));
  return w.take();
}

Result<SequenceInfo> read_file_header(std::string_view bytes, size_t* header_size,
                                      StreamFormat* format) {
  if (bytes.size() < 12 || !magic_is(bytes, kFileMagic))
    return corrupt_data("header: not a .gvid stream (magic 'GVID' missing)");
  ByteReader r(bytes.substr(4));
  StreamFormat f;
  f.major = r.u8();
  f.minor = r.u8();
  const uint8_t profile_idc = r.u8(), reserved = r.u8();
  const uint32_t size = r.u32();
  const bool current = f.major == kMajorVersion && f.minor == kMinorVersion;
  if (!current && !(f.legacy() && f.minor <= kLegacyMaxMinorVersion))
    return unsupported("header: version " + std::to_string(f.major) + "." +
                       std::to_string(f.minor) + " (this build reads " +
                       std::to_string(kMajorVersion) + "." + std::to_string(kMinorVersion) +
                       " and the legacy 1.0 to 1." + std::to_string(kLegacyMaxMinorVersion) + ")");
  if (size < kFixedHeaderSize + 4 || size > bytes.size())
    return corrupt_data("header: header size " + std::to_string(size) + " out of range");
  const uint32_t stored_crc = ByteReader(bytes.substr(size - 4)).u32();
  if (crc32(bytes.data(), size - 4) != stored_crc) return corrupt_data("header: CRC mismatch");
  if (f.legacy()) {
    f.profile = Profile::kAuto;  // bytes 6-7 reserved in 1.x
  } else {
    auto profile = profile_from_idc(profile_idc);
    if (!profile.is_ok()) return profile.status().with_context("header");
    f.profile = *profile;
    if (reserved != 0)
      return unsupported("header: byte 7 is " + std::to_string(reserved) +
                         " (reserved in format 2.0: 0)");
  }
  SequenceInfo info;
  info.width = static_cast<int>(std::min<uint32_t>(r.u32(), 1u << 30));
  info.height = static_cast<int>(std::min<uint32_t>(r.u32(), 1u << 30));
  info.bit_depth = r.u8();
  const uint8_t planes = r.u8();
  r.u16();
  info.fps = r.f64();
  for (int a = 0; a < 3; ++a) info.box_min_mm[a] = r.f64();
  for (int a = 0; a < 3; ++a) info.box_max_mm[a] = r.f64();
  const uint32_t mask_bytes = r.u32();
  if (!r.ok()) return corrupt_data("header: truncated");
  if ((planes & (kPlaneX | kPlaneY | kPlaneZ)) != (kPlaneX | kPlaneY | kPlaneZ) || planes > 15)
    return corrupt_data("header: planes " + std::to_string(planes) + " (X, Y and Z required)");
  info.has_texture = (planes & kPlaneTexture) != 0;
  if (info.width < 1 || info.height < 1 || info.width > kMaxDimension ||
      info.height > kMaxDimension)
    return corrupt_data("header: size " + std::to_string(info.width) + "x" +
                        std::to_string(info.height) + " out of range");
  if (kFixedHeaderSize + static_cast<size_t>(mask_bytes) + 4 != size)
    return corrupt_data("header: mask size " + std::to_string(mask_bytes) +
                        " inconsistent with header size");
  auto mask = decode_mask(bytes.substr(kFixedHeaderSize, mask_bytes), info.width, info.height);
  if (!mask.is_ok()) return mask.status().with_context("header: domain mask");
  info.domain_mask = std::move(mask).value();
  GVKIT_RETURN_IF_ERROR(info.check().with_context("header"));
  *header_size = size;
  if (format) *format = f;
  return info;
}

Status check_packet_conformance(const StreamFormat& format, const PacketHeader& header,
                                std::string_view payload) {
  if (format.legacy()) return Status::ok();
  if (!header.compact)
    return corrupt_data("full packet header ('GVFR') in a format 2.0 stream (compact 'gv' only)");
  if (!payload.empty() && !(static_cast<uint8_t>(payload[0]) & kPayloadCompactSegments))
    return corrupt_data(
        "payload flags: u32 segment sizes in a format 2.0 stream (bit 4, compact sizes, is "
        "required)");
  const std::string profile = std::string("profile ") + profile_name(format.profile);
  if (format.profile == Profile::kIntra && header.type != FrameType::kIntra)
    return corrupt_data(profile + ": a " + frame_type_name(header.type) + " frame (I frames only)");
  if (format.profile == Profile::kLossless && !(header.flags & kFrameLossless))
    return corrupt_data(profile + ": a lossy frame (flags bit 0, transform bypass, is required)");
  return Status::ok();
}

std::string write_packet_header(const PacketHeader& h) {
  ByteWriter w;
  // Magic, then type, flags, qp and flags2 in both forms.
  const auto start = [&](std::string_view magic) {
    w.bytes(magic);
    w.u8(static_cast<uint8_t>(static_cast<uint8_t>(h.type) |
                              (h.half_resolution ? kPacketTypeHalfResolution : 0)));
    w.u8(h.flags);
    w.u8(static_cast<uint8_t>(static_cast<int8_t>(h.qp)));
    w.u8(h.flags2);
  };
  if (h.compact) {
    start(std::string_view(kCompactPacketMagic, 2));
    w.varint(h.frame_number);
    w.varint(h.payload_size);
    w.u32(h.payload_crc);
    w.u8(crc8(w.str()));
    return w.take();
  }
  start(std::string_view(kPacketMagic, 4));
  w.u32(h.frame_number);
  w.u32(h.payload_size);
  w.u32(h.payload_crc);
  w.u32(crc32(w.str()));
  return w.take();
}

bool starts_with_packet_magic(std::string_view bytes) {
  return magic_is(bytes, kPacketMagic) ||
         (bytes.size() >= 2 && std::memcmp(bytes.data(), kCompactPacketMagic, 2) == 0);
}

namespace {
// The type byte: the frame type and the half-resolution bit.
void read_type(PacketHeader& h, uint8_t byte) {
  h.half_resolution = (byte & kPacketTypeHalfResolution) != 0;
  h.type = static_cast<FrameType>(byte & ~kPacketTypeHalfResolution);
}
}  // namespace

Result<PacketHeader> read_packet_header(std::string_view bytes) {
  PacketHeader h;
  if (bytes.size() >= 2 && std::memcmp(bytes.data(), kCompactPacketMagic, 2) == 0) {
    // The compact header: varints of at most 5 bytes (values below 2^32).
    const std::string_view fields = bytes.substr(2, kCompactPacketHeaderMaxSize - 2);
    ByteReader r(fields);
    h.compact = true;
    read_type(h, r.u8());
    h.flags = r.u8();
    h.qp = static_cast<int8_t>(r.u8());
    h.flags2 = r.u8();
    const uint64_t number = r.varint(), size = r.varint();
    h.payload_crc = r.u32();
    const size_t crc_at = 2 + (fields.size() - r.remaining());  // bytes the CRC-8 covers
    const uint8_t header_crc = r.u8();
    if (!r.ok()) return corrupt_data("packet header truncated");
    if (number > UINT32_MAX || size > UINT32_MAX)
      return corrupt_data("packet header: frame number or payload size out of range");
    if (crc8(bytes.data(), crc_at) != header_crc) return corrupt_data("packet header CRC mismatch");
    h.frame_number = static_cast<uint32_t>(number);
    h.payload_size = static_cast<uint32_t>(size);
    h.header_size = static_cast<uint32_t>(crc_at + 1);
    return h;
  }
  if (bytes.size() < kPacketHeaderSize) return corrupt_data("packet header truncated");
  if (!magic_is(bytes, kPacketMagic)) return corrupt_data("packet magic 'GVFR' missing");
  ByteReader r(bytes.substr(4));
  read_type(h, r.u8());
  h.flags = r.u8();
  h.qp = static_cast<int8_t>(r.u8());
  h.flags2 = r.u8();
  h.frame_number = r.u32();
  h.payload_size = r.u32();
  h.payload_crc = r.u32();
  const uint32_t header_crc = r.u32();
  if (crc32(bytes.data(), kPacketHeaderSize - 4) != header_crc)
    return corrupt_data("packet header CRC mismatch");
  return h;
}

std::string write_index(const std::vector<IndexEntry>& entries, uint64_t index_offset) {
  ByteWriter w;
  w.bytes(std::string_view(kIndexMagic, 4));
  w.u32(static_cast<uint32_t>(entries.size()));
  for (const IndexEntry& e : entries) {
    w.u64(e.offset);
    w.u32(e.frame_number);
    w.u32(e.payload_size);
    w.u8(static_cast<uint8_t>(e.type));
    // The packet header's size when it is not the full header's 24 (else 0).
    w.u8(e.header_size == kPacketHeaderSize ? 0 : e.header_size);
    w.u16(0);
  }
  w.u32(crc32(w.str()));
  w.u64(index_offset);
  w.bytes(std::string_view(kTrailerMagic, 4));
  return w.take();
}

Result<std::vector<IndexEntry>> read_index(std::string_view file, size_t header_size,
                                           uint64_t* index_offset) {
  if (file.size() < header_size + kTrailerSize) return corrupt_data("index: no trailer");
  const std::string_view trailer = file.substr(file.size() - kTrailerSize);
  if (!magic_is(trailer.substr(8), kTrailerMagic)) return corrupt_data("index: no trailer");
  const uint64_t offset = ByteReader(trailer).u64();
  // (Compared without offset + 12, which wraps for offsets near 2^64.)
  if (offset < header_size || offset > file.size() - kTrailerSize ||
      file.size() - kTrailerSize - offset < 12)
    return corrupt_data("index: offset out of range");
  const std::string_view block = file.substr(offset, file.size() - kTrailerSize - offset);
  if (!magic_is(block, kIndexMagic)) return corrupt_data("index: magic 'GVIX' missing");
  ByteReader r(block.substr(4));
  const uint32_t count = r.u32();
  if (static_cast<uint64_t>(count) * kIndexEntrySize + 12 != block.size())
    return corrupt_data("index: entry count inconsistent with its size");
  if (crc32(block.data(), block.size() - 4) != ByteReader(block.substr(block.size() - 4)).u32())
    return corrupt_data("index: CRC mismatch");
  std::vector<IndexEntry> entries(count);
  uint64_t expected = header_size;
  for (IndexEntry& e : entries) {
    e.offset = r.u64();
    e.frame_number = r.u32();
    e.payload_size = r.u32();
    e.type = static_cast<FrameType>(r.u8());
    const uint8_t header_size = r.u8();
    r.u16();
    if (header_size != 0 &&
        (header_size < kCompactPacketHeaderMinSize || header_size > kCompactPacketHeaderMaxSize))
      return corrupt_data("index: packet header size " + std::to_string(header_size) +
                          " out of range");
    e.header_size = header_size == 0 ? kPacketHeaderSize : header_size;
    if (e.offset != expected) return corrupt_data("index: entry offsets not contiguous");
    expected = e.offset + e.packet_size();
    if (expected > offset) return corrupt_data("index: entry beyond the packets");
  }
  *index_offset = offset;
  return entries;
}

std::string encode_mask(const cv::Mat& mask) {
  ByteWriter runs;
  uint64_t run = 0, count = 0;
  bool inside = false;
  ByteWriter body;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if ((m[x] != 0) != inside) {
        body.varint(run);
        ++count;
        run = 0;
        inside = !inside;
      }
      ++run;
    }
  }
  body.varint(run);
  ++count;
  runs.varint(count);
  runs.bytes(body.str());
  return runs.take();
}

Result<cv::Mat> decode_mask(std::string_view bytes, int width, int height) {
  ByteReader r(bytes);
  const uint64_t total = static_cast<uint64_t>(width) * height;
  const uint64_t count = r.varint();
  if (!r.ok() || count == 0 || count > total + 1) return corrupt_data("bad run count");
  cv::Mat mask(height, width, CV_8U, cv::Scalar(0));
  uint64_t pos = 0;
  for (uint64_t i = 0; i < count; ++i) {
    const uint64_t run = r.varint();
    if (!r.ok() || run > total - pos) return corrupt_data("runs exceed the picture");
    if (i % 2 == 1)
      for (uint64_t k = pos; k < pos + run; ++k) mask.data[k] = 255;
    pos += run;
  }
  if (pos != total) return corrupt_data("runs do not cover the picture");
  if (r.remaining() != 0) return corrupt_data("trailing bytes after the runs");
  return mask;
}

}  // namespace gvkit::codec::format
