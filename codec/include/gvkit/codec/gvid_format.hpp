#pragma once
// The .gvid byte layout shared by GvidWriter and GvidReader (the field-by-field specification is
// docs/bitstream.md): file header, frame packet header, seek index and trailer. All integers are
// little-endian.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec::format {

inline constexpr char kFileMagic[4] = {'G', 'V', 'I', 'D'};
inline constexpr char kPacketMagic[4] = {'G', 'V', 'F', 'R'};
// Format 1.10: the compact packet header starts with these two bytes instead of `GVFR`.
inline constexpr char kCompactPacketMagic[2] = {'g', 'v'};
inline constexpr char kIndexMagic[4] = {'G', 'V', 'I', 'X'};
inline constexpr char kTrailerMagic[4] = {'G', 'V', 'I', 'E'};
inline constexpr uint8_t kMajorVersion = 1;
inline constexpr uint8_t kMinorVersion = 5;
// A stream without B frames is written as version 1.4 (it uses no 1.5 syntax).
inline constexpr uint8_t kMinorVersionWithoutBFrames = 4;
// Format 1.6 (multiple reference frames): written only when the encoder's options turn it on.
inline constexpr uint8_t kMinorVersionMultiRef = 6;
// P frames with multiple reference frames (1.6): at most this many references.
inline constexpr int kMaxReferenceFrames = 5;
// A stream with larger transforms (format 1.6, docs/bitstream.md 4.8) is written as 1.6.
inline constexpr uint8_t kMinorVersionLargeTransforms = 6;
// A stream with cross-plane residual prediction (flags2 bit 3) is written as version 1.6.
inline constexpr uint8_t kMinorVersionCrossPlane = 6;
// Format 1.7: a stream with cross-plane contexts (flags2 bit 4) is written as version 1.7.
inline constexpr uint8_t kMinorVersionCrossPlaneContexts = 7;
// A stream with inter partitions (flags2 bit 5, docs/bitstream.md 4.11) is written as 1.7.
inline constexpr uint8_t kMinorVersionPartitions = 7;
// Format 1.8: a stream with the deblocking filter (flags2 bit 6, docs/bitstream.md 4.12).
inline constexpr uint8_t kMinorVersionDeblocking = 8;
// Format 1.9: a stream with temporal contexts (flags2 bit 7, docs/bitstream.md 4.13) or compact
// segment sizes (the payload's first byte, bit 4; docs/bitstream.md 2.1).
inline constexpr uint8_t kMinorVersionTemporalContexts = 9;
inline constexpr uint8_t kMinorVersionCompactSegments = 9;
// Format 1.10: a stream with compact packet headers (docs/bitstream.md 2).
inline constexpr uint8_t kMinorVersionCompactPackets = 10;
// Format 1.11: a stream with merge (the payload's first byte, bit 5).
inline constexpr uint8_t kMinorVersionMerge = 11;
// Format 1.12: a stream with TD16 (the payload's first byte, bit 6).
inline constexpr uint8_t kMinorVersionTd16 = 12;
// Format 1.13: a stream with the quadratic intra mode (the payload's first byte, bit 7).
inline constexpr uint8_t kMinorVersionQuadraticIntra = 13;
// Format 1.14: a stream that may code frames at half resolution (the packet type byte, bit 4).
inline constexpr uint8_t kMinorVersionHalfResolution = 14;

// The payload's first byte: the plane count in bits 0-3 and, since 1.9, payload flags above.
enum PayloadFlag : uint8_t {
  kPayloadPlaneCount = 15,
  // since 1.9: every plane segment but the last is preceded by its size as a varint, the last
  // one takes the rest of the payload (before: a u32 size before each).
  kPayloadCompactSegments = 16,
  // since 1.11, P frames: skip and 16x16 inter macroblocks code whether they take one of up to
  // four neighbours' vectors (merge, docs/bitstream.md 4.14).
  kPayloadMerge = 32,
  // since 1.12, P frames with TD prediction (frame flag bit 6): a TD macroblock codes whether it
  // predicts the temporal difference with one 16x16 mode (TD16, docs/bitstream.md 4.15).
  kPayloadTd16 = 64,
  // since 1.13, every frame: I16x16 macroblocks may take the quadratic mode (docs/bitstream.md
  // 6.1). The last bit of this byte.
  kPayloadQuadraticIntra = 128,
  kPayloadKnown = kPayloadPlaneCount | kPayloadCompactSegments | kPayloadMerge | kPayloadTd16 |
                  kPayloadQuadraticIntra,  // every bit a reader understands
};

// The full packet header (`GVFR`, every version); the compact one (format 1.10, `gv`) is 13 to
// 21 bytes: its frame number and payload size are varints.
inline constexpr size_t kPacketHeaderSize = 24;
inline constexpr size_t kCompactPacketHeaderMinSize = 13;
inline constexpr size_t kCompactPacketHeaderMaxSize = 21;
inline constexpr size_t kIndexEntrySize = 20;
inline constexpr size_t kTrailerSize = 12;
inline constexpr int kMaxDimension = 16384;

enum PlaneFlag : uint8_t { kPlaneX = 1, kPlaneY = 2, kPlaneZ = 4, kPlaneTexture = 8 };
// Packets are in decode order: a B frame (1.5) follows the anchor (I or P frame) after it in
// display order; frame_number is the display index.
enum class FrameType : uint8_t { kIntra = 0, kPredicted = 1, kBidirectional = 2 };
// Format 1.14: bit 4 of the packet header's type byte, the frame is coded at half resolution
// (docs/bitstream.md 2.3); the type is the byte's other bits.
inline constexpr uint8_t kPacketTypeHalfResolution = 16;
// "I", "P" or "B" ("?" for other values).
const char* frame_type_name(FrameType type);
enum FrameFlag : uint8_t {
  kFrameLossless = 1,
  kFrameGeometryModes = 2,
  kFrameAdaptiveLevels = 4,    // since 1.1
  kFrameNearLossless = 8,      // since 1.2: with bit 0, residuals quantized (payload: u16 delta)
  kFrameValuePrediction = 16,  // since 1.2: P frames, affine map of the reference's xyz
  kFramePlaneQp = 32,          // since 1.2: lossy frames, per-plane QP offsets
  kFrameTdPrediction = 64,     // since 1.2: P frames, temporal-difference prediction
  kFrameQuarterPel = 128,      // since 1.3: P frames, motion vectors in quarter samples
};
// Packet header byte 7 (reserved, 0, before 1.4): more frame flags.
enum FrameFlag2 : uint8_t {
  kFrame2SharedMotion = 1,  // since 1.4: P frames, Y and Z may take over X's motion per MB
  kFrame2MultiRef = 2,      // since 1.6: P frames, 2..5 reference frames (payload: u8 ref_count)
  // since 1.6: lossy frames, 8x8 / 16x16 transforms of inter and I16x16 residuals (payload: u8
  // max transform, 8 or 16; docs/bitstream.md 4.8)
  kFrame2LargeTransforms = 4,
  kFrame2CrossPlane = 8,           // since 1.6: Y and Z may add a scaled X residual per MB (4.9)
  kFrame2CrossPlaneContexts = 16,  // since 1.7: Y and Z contexts start as X's final (4.10)
  kFrame2Partitions = 32,          // since 1.7: P frames, 16x8 / 8x16 / 8x8 inter partitions (4.11)
  // since 1.8: lossy frames, every plane deblocked after its last macroblock (payload: u8 beta,
  // u8 tc; docs/bitstream.md 4.12)
  kFrame2Deblocking = 64,
  // since 1.9: P and B frames, every plane's contexts start from the same plane's final states
  // in reference 0 (docs/bitstream.md 4.13); not with bit 4. The last bit of flags2: a later
  // tool must announce itself in the payload.
  kFrame2TemporalContexts = 128,
};

struct PacketHeader {
  FrameType type = FrameType::kIntra;
  uint8_t flags = 0;
  uint8_t flags2 = 0;  // FrameFlag2 bits (1.4)
  int qp = 0;          // QP in 8-bit units (signed)
  uint32_t frame_number = 0;
  uint32_t payload_size = 0;
  uint32_t payload_crc = 0;
  bool half_resolution = false;  // format 1.14: the type byte's bit 4
  // Written: the compact header (format 1.10) instead of the full one. Read: which one it was.
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
  uint8_t header_size = kPacketHeaderSize;  // of the packet header, bytes (format 1.10)
  // The packet's length: header and payload, bytes.
  uint64_t packet_size() const { return uint64_t{header_size} + payload_size; }
};

// File header: magic, version (1.minor_version), sequence fields, domain mask, CRC.
std::string write_file_header(const SequenceInfo& info, uint8_t minor_version = kMinorVersion);
// Parses the header at the start of bytes; on success *header_size is its length in bytes.
// Fails naming the field that is missing, out of range or inconsistent.
Result<SequenceInfo> read_file_header(std::string_view bytes, size_t* header_size);

// The full header, or with header.compact the compact one (format 1.10).
std::string write_packet_header(const PacketHeader& header);
// Parses the packet header at the start of bytes, full (`GVFR`) or compact (`gv`, format 1.10);
// checks magic and header CRC only. header_size in the result says where the payload starts.
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
