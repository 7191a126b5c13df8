#include "draco_peer.hpp"

#include <time.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <draco/point_cloud/point_cloud.h>

#include "gvkit/player/geometry_image_mesh.hpp"
#include "nearest_point_grid.hpp"

namespace gvkit::bench {
namespace {

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

Status from_draco(const draco::Status& s, const std::string& what) {
  return unsupported("draco " + what + ": " + s.error_msg_string());
}

// Fills pc (a draco::PointCloud or draco::Mesh) with float positions, one point per vertex.
void add_positions(const std::vector<float>& xyz, draco::PointCloud& pc) {
  const auto n = static_cast<uint32_t>(xyz.size() / 3);
  pc.set_num_points(n);
  draco::GeometryAttribute ga;
  ga.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
          sizeof(float) * 3, 0);
  const int id = pc.AddAttribute(ga, true, n);
  draco::PointAttribute* att = pc.attribute(id);
  for (uint32_t i = 0; i < n; ++i)
    att->SetAttributeValue(draco::AttributeValueIndex(i), &xyz[3 * static_cast<size_t>(i)]);
}

// Mean distance between horizontally neighbouring domain pixels: the cell of the point grid.
double mean_spacing_mm(const GeometryImage& frame) {
  double sum = 0;
  int64_t count = 0;
  for (int y = 0; y < frame.xyz_mm.rows; ++y) {
    const auto* p = frame.xyz_mm.ptr<cv::Vec3f>(y);
    const auto* m = frame.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x + 1 < frame.xyz_mm.cols; ++x)
      if (m[x] && m[x + 1]) {
        sum += cv::norm(p[x + 1] - p[x]);
        ++count;
      }
  }
  return count && sum > 0 ? sum / count : 1.0;
}

}  // namespace

const char* draco_geometry_name(DracoGeometry geometry) {
  return geometry == DracoGeometry::kMesh ? "mesh" : "point cloud";
}

Status DracoOptions::check() const {
  if (quantization_bits < 1 || quantization_bits > 30)
    return invalid_argument("draco quantization bits " + std::to_string(quantization_bits) +
                            " out of range (1..30)");
  if (compression_level < 0 || compression_level > 10)
    return invalid_argument("draco compression level " + std::to_string(compression_level) +
                            " out of range (0..10)");
  return Status::ok();
}

Result<DracoFrameResult> draco_round_trip(const GeometryImage& frame,
                                          const codec::SequenceInfo& info,
                                          const DracoOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  player::GeometryImageMeshOptions mesh_options;  // partial quads on: every rim pixel in a face
  const player::MeshBuffers buffers = player::mesh_buffers_from_geometry_image(frame, mesh_options);
  if (buffers.vertex_count() == 0) return invalid_argument("draco peer: frame has no domain pixel");

  draco::Encoder encoder;
  const int speed = 10 - options.compression_level;
  encoder.SetSpeedOptions(speed, speed);
  if (options.sequence_box) {
    const float origin[3] = {static_cast<float>(info.box_min_mm[0]),
                             static_cast<float>(info.box_min_mm[1]),
                             static_cast<float>(info.box_min_mm[2])};
    double range = 0;
    for (int a = 0; a < 3; ++a) range = std::max(range, info.box_max_mm[a] - info.box_min_mm[a]);
    range *= 1 + 1e-6;  // float rounding must not put the box's far face outside Draco's range
    encoder.SetAttributeExplicitQuantization(draco::GeometryAttribute::POSITION,
                                             options.quantization_bits, 3, origin,
                                             static_cast<float>(range));
  } else {
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.quantization_bits);
  }

  DracoFrameResult out;
  out.input_points = static_cast<int64_t>(buffers.vertex_count());
  draco::EncoderBuffer encoded;
  draco::Decoder decoder;
  std::unique_ptr<draco::PointCloud> decoded;
  if (options.geometry == DracoGeometry::kMesh) {
    draco::Mesh mesh;
    add_positions(buffers.positions_mm, mesh);
    for (size_t t = 0; t < buffers.indices.size(); t += 3)
      mesh.AddFace({draco::PointIndex(buffers.indices[t]),
                    draco::PointIndex(buffers.indices[t + 1]),
                    draco::PointIndex(buffers.indices[t + 2])});
    encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    const double t0 = cpu_seconds();
    const draco::Status s = encoder.EncodeMeshToBuffer(mesh, &encoded);
    out.encode_seconds = cpu_seconds() - t0;
    if (!s.ok()) return from_draco(s, "mesh encode");
    draco::DecoderBuffer in;
    in.Init(encoded.data(), encoded.size());
    const double t1 = cpu_seconds();
    auto mesh_or = decoder.DecodeMeshFromBuffer(&in);
    out.decode_seconds = cpu_seconds() - t1;
    if (!mesh_or.ok()) return from_draco(mesh_or.status(), "mesh decode");
    decoded = std::move(mesh_or).value();
  } else {
    draco::PointCloud cloud;
    add_positions(buffers.positions_mm, cloud);
    encoder.SetEncodingMethod(draco::POINT_CLOUD_KD_TREE_ENCODING);
    const double t0 = cpu_seconds();
    const draco::Status s = encoder.EncodePointCloudToBuffer(cloud, &encoded);
    out.encode_seconds = cpu_seconds() - t0;
    if (!s.ok()) return from_draco(s, "point cloud encode");
    draco::DecoderBuffer in;
    in.Init(encoded.data(), encoded.size());
    const double t1 = cpu_seconds();
    auto cloud_or = decoder.DecodePointCloudFromBuffer(&in);
    out.decode_seconds = cpu_seconds() - t1;
    if (!cloud_or.ok()) return from_draco(cloud_or.status(), "point cloud decode");
    decoded = std::move(cloud_or).value();
  }
  out.bytes = static_cast<int64_t>(encoded.size());

  const draco::PointAttribute* att = decoded->GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (!att) return unsupported("draco decode: no position attribute");
  std::vector<cv::Vec3f> points(decoded->num_points());
  for (uint32_t i = 0; i < decoded->num_points(); ++i)
    if (!att->ConvertValue<float, 3>(att->mapped_index(draco::PointIndex(i)), &points[i][0]))
      return unsupported("draco decode: position " + std::to_string(i) + " unreadable");
  out.decoded_points = static_cast<int64_t>(points.size());

  // Draco reorders (and may split) vertices: each pixel takes the nearest decoded point.
  const NearestPointGrid grid(std::move(points), mean_spacing_mm(frame));
  out.decoded = frame;
  out.decoded.xyz_mm = frame.xyz_mm.clone();
  for (int32_t pixel : buffers.pixel_index) {
    cv::Vec3f& p =
        out.decoded.xyz_mm.at<cv::Vec3f>(pixel / frame.xyz_mm.cols, pixel % frame.xyz_mm.cols);
    const int64_t k = grid.nearest(p);
    if (k >= 0) p = grid.points()[k];
  }
  return out;
}

}  // namespace gvkit::bench
