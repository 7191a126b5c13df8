#include "gvkit/codec/frame_coding.hpp"

#include <string>
#include <vector>

#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {
namespace {

const char* const kPlaneNames[4] = {"X", "Y", "Z", "T"};

PlaneCodingParams plane_params(const SequenceInfo& info, int plane, uint8_t flags, int qp) {
  PlaneCodingParams p;
  p.bit_depth = plane < 3 ? info.bit_depth : 8;
  p.lossless = (flags & format::kFrameLossless) != 0;
  p.geometry_modes = (flags & format::kFrameGeometryModes) != 0;
  p.adaptive_levels = (flags & format::kFrameAdaptiveLevels) != 0;
  p.qp_prime = std::clamp(qp + 6 * (p.bit_depth - 8), 0, 51 + 6 * (p.bit_depth - 8));
  return p;
}

}  // namespace

Result<EncodedFrame> encode_frame(const GeometryImage& image, const SequenceInfo& info,
                                  const EncoderOptions& options, uint32_t frame_number,
                                  const std::vector<SamplePlane>* reference) {
  const std::string name = "frame " + std::to_string(frame_number);
  if (image.xyz_mm.rows != info.height || image.xyz_mm.cols != info.width)
    return invalid_argument(name + ": size differs from the sequence's");
  GVKIT_RETURN_IF_ERROR(image.check().with_context(name));
  if (info.has_texture && image.texture.empty())
    return invalid_argument(name + ": texture missing (the sequence has a texture plane)");
  const std::vector<SamplePlane> planes = quantize_geometry(image, info);
  format::PacketHeader header;
  header.type = reference ? format::FrameType::kPredicted : format::FrameType::kIntra;
  GVKIT_CHECK(!reference || reference->size() == planes.size());
  header.flags = static_cast<uint8_t>(
      (options.lossless ? format::kFrameLossless | format::kFrameAdaptiveLevels : 0) |
      (options.geometry_modes ? format::kFrameGeometryModes : 0));
  header.qp = options.lossless ? 0 : options.qp;
  header.frame_number = frame_number;
  ByteWriter payload;
  payload.u8(static_cast<uint8_t>(planes.size()));
  std::vector<SamplePlane> recon;
  for (size_t i = 0; i < planes.size(); ++i) {
    PlaneCodingParams p = plane_params(info, static_cast<int>(i), header.flags, header.qp);
    p.rdo = options.preset == Preset::kSlow;
    p.allow_8x8 = options.preset == Preset::kSlow;
    p.search_range = options.search_range;
    PlaneEncodeResult coded = encode_plane(planes[i], p, reference ? &(*reference)[i] : nullptr);
    payload.u32(static_cast<uint32_t>(coded.bytes.size()));
    payload.bytes(coded.bytes);
    recon.push_back(std::move(coded.reconstruction));
  }
  header.payload_size = static_cast<uint32_t>(payload.size());
  header.payload_crc = crc32(payload.str());
  EncodedFrame out;
  out.packet = format::write_packet_header(header) + payload.str();
  out.reconstruction = dequantize_geometry(recon, info, frame_number);
  out.planes = std::move(recon);
  return out;
}

Result<GeometryImage> decode_frame_packet(std::string_view packet, const SequenceInfo& info,
                                          int64_t frame_number,
                                          const std::vector<SamplePlane>* reference,
                                          std::vector<SamplePlane>* planes_out) {
  GVKIT_ASSIGN_OR_RETURN(const format::PacketHeader header, format::read_packet_header(packet));
  if (packet.size() - format::kPacketHeaderSize < header.payload_size)
    return corrupt_data("payload truncated");
  const std::string_view payload = packet.substr(format::kPacketHeaderSize, header.payload_size);
  if (crc32(payload.data(), payload.size()) != header.payload_crc)
    return corrupt_data("payload CRC mismatch");
  if (header.type != format::FrameType::kIntra && header.type != format::FrameType::kPredicted)
    return corrupt_data("frame type " + std::to_string(static_cast<int>(header.type)));
  const bool predicted = header.type == format::FrameType::kPredicted;
  if (predicted && (!reference || reference->size() != (info.has_texture ? 4u : 3u)))
    return corrupt_data("P frame without a reference frame");
  if (header.flags > 7) return corrupt_data("frame flags " + std::to_string(header.flags));
  if (!(header.flags & format::kFrameLossless) &&
      (header.qp < -6 * (info.bit_depth - 8) || header.qp > 51))
    return corrupt_data("qp " + std::to_string(header.qp) + " out of range");
  ByteReader r(payload);
  const size_t plane_count = r.u8();
  const size_t expected = info.has_texture ? 4 : 3;
  if (plane_count != expected)
    return corrupt_data("plane count " + std::to_string(plane_count) + " (header says " +
                        std::to_string(expected) + ")");
  const int pw = (info.width + 15) / 16 * 16, ph = (info.height + 15) / 16 * 16;
  std::vector<SamplePlane> planes;
  for (size_t i = 0; i < plane_count; ++i) {
    const std::string name = std::string("plane ") + kPlaneNames[i];
    const uint32_t size = r.u32();
    const std::string_view bytes = r.bytes(size);
    if (!r.ok()) return corrupt_data(name + ": segment size exceeds the payload");
    auto plane = decode_plane(bytes, pw, ph,
                              plane_params(info, static_cast<int>(i), header.flags, header.qp),
                              predicted ? &(*reference)[i] : nullptr);
    if (!plane.is_ok()) return plane.status().with_context(name);
    planes.push_back(std::move(plane).value());
  }
  if (r.remaining() != 0) return corrupt_data("trailing bytes after the planes");
  GeometryImage image = dequantize_geometry(planes, info, frame_number);
  if (planes_out) *planes_out = std::move(planes);
  return image;
}

}  // namespace gvkit::codec
