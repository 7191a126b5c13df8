// gvkit info FILE: describes an EXR, a mesh, an image or a calibration file.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "command.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/mesh_topology.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;

// Finite min/max/mean and the count of non-finite values of a CV_32F plane.
void print_plane_range(const std::string& name, const cv::Mat& plane) {
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  int64_t finite = 0;
  for (int y = 0; y < plane.rows; ++y) {
    const float* p = plane.ptr<float>(y);
    for (int x = 0; x < plane.cols; ++x) {
      if (!std::isfinite(p[x])) continue;
      lo = std::min(lo, static_cast<double>(p[x]));
      hi = std::max(hi, static_cast<double>(p[x]));
      sum += p[x];
      ++finite;
    }
  }
  const int64_t non_finite = static_cast<int64_t>(plane.total()) - finite;
  if (finite == 0) {
    std::printf("  %-4s no finite values\n", name.c_str());
    return;
  }
  std::printf("  %-4s min %12.5g  max %12.5g  mean %12.5g  non-finite %lld\n", name.c_str(), lo, hi,
              sum / static_cast<double>(finite), static_cast<long long>(non_finite));
}

void describe_exr(const fs::path& path) {
  ExrChannels channels = value_or_throw(read_exr(path));
  const cv::Size size = channels.begin()->second.size();
  std::printf("%s: OpenEXR, %dx%d, %zu channels\n", path.string().c_str(), size.width, size.height,
              channels.size());
  for (const auto& [name, plane] : channels) print_plane_range(name, plane);
}

void describe_mesh(const fs::path& path) {
  Mesh mesh = value_or_throw(read_mesh(path));
  const MeshTopology t = mesh_topology(mesh);
  std::printf("%s: mesh\n", path.string().c_str());
  std::printf("  vertices        %zu (%d isolated)\n", mesh.n_vertices(), t.isolated_vertices);
  std::printf("  faces           %zu triangles\n", mesh.n_faces());
  std::printf("  edges           %d\n", t.edges);
  std::printf("  components      %d\n", t.components);
  std::printf("  boundary loops  %d", t.boundary_loops);
  if (!t.boundary_loop_lengths.empty()) {
    std::printf(" (edges:");
    for (int n : t.boundary_loop_lengths) std::printf(" %d", n);
    std::printf(")");
  }
  std::printf("\n  euler           %d\n", t.euler_characteristic);
  if (t.genus >= 0)
    std::printf("  genus           %d\n", t.genus);
  else
    std::printf("  genus           n/a (%d components)\n", t.components);
  std::printf("  colours         %s\n  texcoords       %s\n",
              mesh.has_vertex_colors() ? "yes" : "no",
              mesh.has_vertex_texcoords2D() ? "yes" : "no");
  Mesh::Point lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  std::printf("  bounding box    [%.4g %.4g %.4g] .. [%.4g %.4g %.4g]\n", lo[0], lo[1], lo[2],
              hi[0], hi[1], hi[2]);
}

void describe_image(const fs::path& path) {
  cv::Mat image = value_or_throw(read_image(path));
  double lo = 0, hi = 0;
  cv::minMaxLoc(image.reshape(1), &lo, &hi);
  std::printf("%s: image, %dx%d, %d channel(s), %d-bit, values %g..%g\n", path.string().c_str(),
              image.cols, image.rows, image.channels(), image.depth() == CV_16U ? 16 : 8, lo, hi);
}

void print_matrix(const char* name, const cv::Matx33d& m) {
  std::printf("  %s\n", name);
  for (int r = 0; r < 3; ++r)
    std::printf("    [%14.6f %14.6f %14.6f]\n", m(r, 0), m(r, 1), m(r, 2));
}

void print_vector(const char* name, const std::vector<double>& v) {
  std::printf("  %-28s", name);
  if (v.empty()) std::printf(" none");
  for (double x : v) std::printf(" %.6g", x);
  std::printf("\n");
}

void describe_calibration(const fs::path& path) {
  // Layouts without device sizes (procam, stereo_calib) are described all the same: a stand-in
  // size lets the file be read, and the sizes are reported as not recorded.
  CalibrationReadOptions stand_in;
  stand_in.camera_size = stand_in.projector_size = {1, 1};
  Result<LoadedCalibration> read = read_calibration(path);
  if (!read) {
    Result<LoadedCalibration> sizeless = read_calibration(path, stand_in);
    if (!sizeless || (sizeless->camera_size_from_file && sizeless->projector_size_from_file))
      throw CommandFailed(read.status());
    read = sizeless;
  }
  const LoadedCalibration& loaded = *read;
  const Calibration& c = loaded.calibration;
  std::printf("%s: calibration (%s layout)\n", path.string().c_str(),
              calibration_format_name(loaded.format));
  if (loaded.camera_size_from_file)
    std::printf("  camera      %dx%d px\n", c.camera_width, c.camera_height);
  else
    std::printf("  camera      size not recorded (taken from the images)\n");
  print_matrix("camera K (px)", c.camera_K);
  print_vector("camera distortion", c.camera_dist);
  if (loaded.projector_size_from_file)
    std::printf("  projector   %dx%d px\n", c.projector_width, c.projector_height);
  else
    std::printf("  projector   size not recorded (give --projector-size)\n");
  print_matrix("projector K (px)", c.projector_K);
  print_vector("projector distortion", c.projector_dist);
  print_matrix("R cam_from_proj", c.R_cam_from_proj);
  std::printf("  t cam_from_proj (mm)         %.4f %.4f %.4f\n", c.t_cam_from_proj_mm[0],
              c.t_cam_from_proj_mm[1], c.t_cam_from_proj_mm[2]);
  std::printf("  baseline (mm)                %.4f\n", c.baseline_mm());
  const cv::Vec3d axis(0, 0, 1);
  const double angle = std::acos(std::clamp((c.R_cam_from_proj * axis).dot(axis), -1.0, 1.0));
  std::printf("  angle between optical axes   %.3f deg\n", angle * 180.0 / CV_PI);
  if (c.fringe_pitch_px > 0)
    std::printf("  fringe pitch (px)            %.4f\n", c.fringe_pitch_px);
  if (c.stereo_error_px >= 0)
    std::printf("  reprojection error (px)      camera %.4f  projector %.4f  stereo %.4f\n",
                c.camera_error_px, c.projector_error_px, c.stereo_error_px);
}

void describe_gvid(const fs::path& path) {
  auto reader = value_or_throw(codec::GvidReader::open(path));
  const codec::SequenceInfo& info = reader->info();
  std::printf("%s: .gvid geometry video, %lld bytes\n", path.string().c_str(),
              static_cast<long long>(reader->file_bytes()));
  const codec::format::StreamFormat& format = reader->format();
  if (format.legacy())
    std::printf("  format          %d.%d (legacy 1.x, read-only: gvkit writes format 2.0)\n",
                format.major, format.minor);
  else
    std::printf("  format          %d.%d, profile %s\n", format.major, format.minor,
                codec::profile_name(format.profile));
  std::printf("  size            %dx%d, %d-bit xyz%s\n", info.width, info.height, info.bit_depth,
              info.has_texture ? " + 8-bit texture" : "");
  std::printf("  fps             %g\n", info.fps);
  std::printf("  domain pixels   %lld\n", static_cast<long long>(info.domain_pixels()));
  std::printf("  box (mm)        [%.4f %.4f %.4f] .. [%.4f %.4f %.4f], diagonal %.3f\n",
              info.box_min_mm[0], info.box_min_mm[1], info.box_min_mm[2], info.box_max_mm[0],
              info.box_max_mm[1], info.box_max_mm[2], info.box_diagonal_mm());
  std::printf("  step (mm)       %.6g\n", info.step_mm());
  std::printf("  header          %lld bytes\n", static_cast<long long>(reader->header_bytes()));
  std::printf("  frames          %lld%s\n", static_cast<long long>(reader->frame_count()),
              reader->index_rebuilt() ? " (index missing or damaged: found by a scan)" : "");
  int64_t total = 0, count[3] = {0, 0, 0};
  for (int64_t i = 0; i < reader->frame_count(); ++i) {
    const auto type = static_cast<size_t>(reader->frame_type(i));
    if (type < 3) ++count[type];
  }
  std::printf("  frame types     %lld I, %lld P, %lld B\n", static_cast<long long>(count[0]),
              static_cast<long long>(count[1]), static_cast<long long>(count[2]));
  // Frames with larger transforms (flags2 bit 2).
  int64_t large_transforms = 0;
  for (int64_t i = 0; i < reader->frame_count(); ++i) {
    const auto header = reader->packet_header(i);
    if (header.is_ok() && (header->flags2 & codec::format::kFrame2LargeTransforms))
      ++large_transforms;
  }
  if (large_transforms > 0)
    std::printf("  transforms      8x8 / 16x16 in %lld of %lld frames\n",
                static_cast<long long>(large_transforms),
                static_cast<long long>(reader->frame_count()));
  const double vertices = static_cast<double>(std::max<int64_t>(1, info.domain_pixels()));
  // Display order; packets are in decode order (a B frame after the anchor that follows it).
  for (int64_t i = 0; i < reader->frame_count(); ++i) {
    const int64_t bits = reader->frame_bits(i);
    total += bits;
    // Frame-level tools of the packet header (flags2, compact header, half resolution), and how
    // many reference frames a P frame with several has.
    std::string tools;
    if (auto h = reader->packet_header(i); h.is_ok()) {
      if (h->flags2 & codec::format::kFrame2SharedMotion) tools += "  shared-motion";
      if (h->flags2 & codec::format::kFrame2CrossPlane) tools += "  cross-plane";
      if (h->flags2 & codec::format::kFrame2CrossPlaneContexts) tools += "  cross-plane-contexts";
      if (h->flags2 & codec::format::kFrame2Partitions) tools += "  partitions";
      if (h->flags2 & codec::format::kFrame2Deblocking) tools += "  deblocking";
      if (h->flags2 & codec::format::kFrame2TemporalContexts) tools += "  temporal-contexts";
      if (!h->compact) tools += "  full-packet-header";  // legacy 1.x streams only
      if (h->half_resolution) tools += "  half-resolution";
    }
    const int refs = reader->frame_type(i) == codec::format::FrameType::kPredicted
                         ? reader->frame_references(i)
                         : 1;
    if (refs > 1) tools += "  refs " + std::to_string(refs);
    std::printf("  frame %6lld    %s  %9lld bytes  %8.4f bits/vertex  (packet %lld)%s\n",
                static_cast<long long>(i), codec::format::frame_type_name(reader->frame_type(i)),
                static_cast<long long>(bits / 8), bits / vertices,
                static_cast<long long>(reader->decode_position(i)), tools.c_str());
  }
  if (reader->frame_count() > 0)
    std::printf("  mean            %.4f bits/vertex/frame, %.1f kbit/s\n",
                total / vertices / reader->frame_count(),
                total / 1000.0 / reader->frame_count() * info.fps);
}

void describe(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw CommandFailed(not_found(path.string() + ": no such file"));
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return describe_exr(path);
  if (ext == ".gvid") return describe_gvid(path);
  if (ext == ".ply" || ext == ".obj" || ext == ".off" || ext == ".stl") return describe_mesh(path);
  if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
      ext == ".tiff" || ext == ".pgm" || ext == ".ppm")
    return describe_image(path);
  if (ext == ".xml" || ext == ".yaml" || ext == ".yml" || ext == ".json")
    return describe_calibration(path);
  throw CommandFailed(unsupported(path.string() + ": unknown file type '" + ext +
                                  "' (gvkit info reads .exr, .gvid, .ply, .obj, .png, "
                                  "calibration .xml/.yaml/.json)"));
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("info", "Describe a file: EXR, .gvid, mesh (PLY/OBJ), image, calibration");
  auto files = std::make_shared<std::vector<std::string>>();
  cmd->add_option("files", *files, "Files to describe")->required();
  cmd->callback([files] {
    for (const auto& f : *files) describe(f);
  });
}

}  // namespace gvkit::tools
