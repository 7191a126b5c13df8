#pragma once
// The .gvid byte layout shared by GvidWriter and GvidReader (the field-by-field specification is
// docs/bitstream.md): file header, frame packet header, seek index and trailer, and the rules a
// format 2.0 stream's profile puts on its packets. All integers are little-endian.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/codec/profile.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec::format {

inline constexpr char kFileMagic[4] = {'G', 'V', 'I', 'D'};
inline constexpr char kPacketMagic[4] = {'G', 'V', 'F', 'R'};
// The compact packet header (every 2.0 packet) starts with these two bytes; the full one
// (`GVFR`, legacy 1.x streams only) with kPacketMagic.
inline constexpr char kCompactPacketMagic[2] = {'g', 'v'};
inline constexpr char kIndexMagic[4] = {'G', 'V', 'I', 'X'};
inline constexpr char kTrailerMagic[4] = {'G', 'V', 'I', 'E'};
// Format 2.0: the version every stream is written as. Its file header carries the profile
// (profile.hpp) in byte 6; its packets are compact (`gv`) with compact segment sizes.
inline constexpr uint8_t kMajorVersion = 2;
inline constexpr uint8_t kMinorVersion = 0;
// The legacy formats 1.0 to 1.14 are still read (docs/bitstream.md, appendix A), never written.
inline constexpr uint8_t kLegacyMajorVersion = 1;
inline constexpr uint8_t kLegacyMaxMinorVersion = 14;
// P frames with multiple reference frames (flags2 bit 1): at most this many references.
inline constexpr int kMaxReferenceFrames = 5;

// The payload's first byte: the plane count in bits 0-3, payload flags above (docs/bitstream.md
// 2.1).
enum PayloadFlag : uint8_t {
  kPayloadPlaneCount = 15,
  // Every plane segment but the last is preceded by its size as a varint, the last one takes
  // the rest of the payload (legacy streams without it: a u32 size before each). Set in every
  // 2.0 packet.
  kPayloadCompactSegments = 16,
  // P frames: skip and 16x16 inter macroblocks code whether they take one of up to four
  // neighbours' vectors (merge, docs/bitstream.md 4.14).
  kPayloadMerge = 32,
  // P frames with TD prediction (frame flag bit 6): a TD macroblock codes whether it predicts
  // the temporal difference with one 16x16 mode (TD16, docs/bitstream.md 4.15).
  kPayloadTd16 = 64,
  // Every frame: I16x16 macroblocks may take the quadratic mode (docs/bitstream.md 6.1).
  kPayloadQuadraticIntra = 128,
  kPayloadKnown = kPayloadPlaneCount | kPayloadCompactSegments | kPayloadMerge | kPayloadTd16 |
                  kPayloadQuadraticIntra,  // every bit a reader understands
};

// The compact packet header (`gv`, every 2.0 packet) is 13 to 21 bytes: its frame number and
// payload size are varints. The full one (`GVFR`, legacy streams) is 24 bytes.
inline constexpr size_t kPacketHeaderSize = 24;
inline constexpr size_t kCompactPacketHeaderMinSize = 13;
inline constexpr size_t kCompactPacketHeaderMaxSize = 21;
inline constexpr size_t kIndexEntrySize = 20;
inline constexpr size_t kTrailerSize = 12;
inline constexpr int kMaxDimension = 16384;

enum PlaneFlag : uint8_t { kPlaneX = 1, kPlaneY = 2, kPlaneZ = 4, kPlaneTexture = 8 };
// Packets are in decode order: a B frame follows the anchor (I or P frame) after it in display
// order; frame_number is the display index.
enum class FrameType : uint8_t { kIntra = 0, kPredicted = 1, kBidirectional = 2 };
// Bit 4 of the packet header's type byte: the frame is coded at half resolution
// (docs/bitstream.md 2.3); the type is the byte's other bits.
inline constexpr uint8_t kPacketTypeHalfResolution = 16;
// "I", "P" or "B" ("?" for other values).
const char* frame_type_name(FrameType type);
// Packet header byte 5 (docs/bitstream.md 2).
enum FrameFlag : uint8_t {
  kFrameLossless = 1,  // transform bypass
  kFrameGeometryModes = 2,
  kFrameAdaptiveLevels = 4,
  kFrameNearLossless = 8,      // with bit 0, residuals quantized (payload: u16 delta)
  kFrameValuePrediction = 16,  // P frames, affine map of the reference's xyz (2.2)
  kFramePlaneQp = 32,          // lossy frames, per-plane QP offsets
  kFrameTdPrediction = 64,     // P frames, temporal-difference prediction
  kFrameQuarterPel = 128,      // P and B frames, motion vectors in quarter samples
};
// Packet header byte 7: more frame flags (docs/bitstream.md 2).
enum FrameFlag2 : uint8_t {
  kFrame2SharedMotion = 1,  // P frames, Y and Z may take over X's motion per MB (4.5)
  kFrame2MultiRef = 2,      // P frames, 2..5 reference frames (payload: u8 ref_count; 4.7)
  // Lossy frames, 8x8 / 16x16 transforms of inter and I16x16 residuals (payload: u8 max
  // transform, 8 or 16; 4.8)
  kFrame2LargeTransforms = 4,
  kFrame2CrossPlane = 8,           // Y and Z may add a scaled X residual per MB (4.9)
  kFrame2CrossPlaneContexts = 16,  // Y and Z contexts start as X's final (4.10)
  kFrame2Partitions = 32,          // P frames, 16x8 / 8x16 / 8x8 inter partitions (4.11)
  // Lossy frames, every plane deblocked after its last macroblock (payload: u8 beta, u8 tc;
  // 4.12)
  kFrame2Deblocking = 64,
  // P and B frames, every plane's contexts start from the same plane's final states in
  // reference 0 (4.13); not with bit 4.
  kFrame2TemporalContexts = 128,
};

struct PacketHeader {
  FrameType type = FrameType::kIntra;
  uint8_t flags = 0;   // FrameFlag bits
  uint8_t flags2 = 0;  // FrameFlag2 bits
  int qp = 0;          // QP in 8-bit units (signed)
  uint32_t frame_number = 0;
  uint32_t payload_size = 0;
  uint32_t payload_crc = 0;
  bool half_resolution = false;  // the type byte's bit 4
  // Written: the compact header instead of the full one (a 2.0 stream's packets are compact).
  // Read: which one it was.
  bool compact = false;
  // Read: the header's length in bytes (kPacketHeaderSize, or 13..21 when compact); the payload
  // follows it.
  uint32_t header_size = kPacketHeaderSize;
};

struct IndexEntry {
  uint64_t offset = 0;  // of the packet header, from the start of the file
  uint32_t frame_number = 0;
  uint32_t payload_size = 0;
  FrameType type = FrameType::kIntra;
  uint8_t header_size = kPacketHeaderSize;  // of the packet header, bytes
  // The packet's length: header and payload, bytes.
  uint64_t packet_size() const { return uint64_t{header_size} + payload_size; }
};

// The version and profile of a stream, from its file header.
struct StreamFormat {
  uint8_t major = kMajorVersion;
  uint8_t minor = kMinorVersion;
  // Format 2.0: the header's profile (never kAuto). A legacy 1.x stream has none: kAuto.
  Profile profile = Profile::kMain;
  bool legacy() const { return major == kLegacyMajorVersion; }
  // "2.0, profile main", or for a legacy stream "1.14 (legacy, read-only)".
  std::string description() const;
};

// File header of format 2.0 with `profile` (contract: not kAuto): magic, version, profile,
// sequence fields, domain mask, CRC.
std::string write_file_header(const SequenceInfo& info, Profile profile = Profile::kMain);
// Parses the header at the start of bytes, format 2.0 or a legacy 1.x one; on success
// *header_size is its length in bytes and *format (optional) its version and profile. Fails
// naming the field that is missing, out of range or inconsistent; an unknown version or profile
// is unsupported.
Result<SequenceInfo> read_file_header(std::string_view bytes, size_t* header_size,
                                      StreamFormat* format = nullptr);

// What a stream's format requires of each of its packets beyond the packet syntax, for a 2.0
// stream (a legacy stream has no such rules): a compact header and compact segment sizes, and
// the profile's constraints (lossless: transform bypass in every frame; intra: I frames only).
// `payload` is checked when not empty (its first byte; pass it once its CRC is verified).
// corrupt_data naming the rule otherwise, e.g. "profile intra: a P frame".
Status check_packet_conformance(const StreamFormat& format, const PacketHeader& header,
                                std::string_view payload);

// The full header, or with header.compact the compact one.
std::string write_packet_header(const PacketHeader& header);
// Parses the packet header at the start of bytes, full (`GVFR`) or compact (`gv`); checks magic
// and header CRC only. header_size in the result says where the payload starts.
Result<PacketHeader> read_packet_header(std::string_view bytes);
// Whether bytes start with either packet magic (full `GVFR`, compact `gv`).
bool starts_with_packet_magic(std::string_view bytes);

// Index block followed by the trailer (which holds the index's offset).
std::string write_index(const std::vector<IndexEntry>& entries, uint64_t index_offset);
// Reads the index via the trailer at the end of file_bytes; fails if absent or inconsistent.
Result<std::vector<IndexEntry>> read_index(std::string_view file_bytes, size_t header_size,
                                           uint64_t* index_offset);

// Domain mask (CV_8U, 0 / nonzero) as alternating run lengths, starting with an outside run.
std::string encode_mask(const cv::Mat& mask);
Result<cv::Mat> decode_mask(std::string_view bytes, int width, int height);

}  // namespace gvkit::codec::format
