#include "gvkit/core/mesh_io.hpp"

// MeshIO must be included before any OpenMesh kernel header that mesh.hpp pulls in.
#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/mesh.hpp"
#include "ply_header.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

// OpenMesh's IO manager and its readers/writers are process-wide singletons with per-call state:
// concurrent reads or writes corrupt each other, so every OpenMesh I/O call holds this lock.
std::mutex& openmesh_io_mutex() {
  static std::mutex mutex;
  return mutex;
}

// OpenMesh reports problems on its own streams; gvkit reports them as Status instead.
void silence_openmesh_logs() {
  static std::once_flag once;
  std::call_once(once, [] {
    omerr().disable();
    omlog().disable();
    omout().disable();
  });
}

}  // namespace

Result<Mesh> read_mesh(const fs::path& path, const MeshReadOptions& options) {
  silence_openmesh_logs();
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".off" && ext != ".stl")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  if (fs::file_size(path, ec) == 0) return corrupt_data(path.string() + ": empty file");
  if (ext == ".ply") GVKIT_RETURN_IF_ERROR(detail::check_ply_structure(path));

  Mesh mesh;
  mesh.request_vertex_colors();
  mesh.request_vertex_texcoords2D();
  mesh.request_halfedge_texcoords2D();
  OpenMesh::IO::Options io_options = OpenMesh::IO::Options::VertexColor |
                                     OpenMesh::IO::Options::VertexTexCoord |
                                     OpenMesh::IO::Options::FaceTexCoord;
  bool ok = false;
  try {
    std::lock_guard<std::mutex> lock(openmesh_io_mutex());
    ok = OpenMesh::IO::read_mesh(mesh, path.string(), io_options);
  } catch (const std::exception& e) {
    return corrupt_data(path.string() + ": cannot parse mesh: " + e.what());
  }
  if (!ok) return corrupt_data(path.string() + ": cannot parse mesh (truncated or malformed)");
  if (mesh.n_faces() == 0) return corrupt_data(path.string() + ": mesh has no faces");

  // OBJ texture coordinates arrive per halfedge (per face corner); give vertices one each.
  if (!io_options.vertex_has_texcoord() && io_options.face_has_texcoord()) {
    for (auto h : mesh.halfedges()) {
      if (mesh.is_boundary(h)) continue;
      mesh.set_texcoord2D(mesh.to_vertex_handle(h), mesh.texcoord2D(h));
    }
    io_options += OpenMesh::IO::Options::VertexTexCoord;
  }
  mesh.release_halfedge_texcoords2D();
  if (!io_options.vertex_has_color()) mesh.release_vertex_colors();
  if (!io_options.vertex_has_texcoord()) mesh.release_vertex_texcoords2D();

  for (auto v : mesh.vertices()) {
    Mesh::Point p = mesh.point(v);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      return corrupt_data(path.string() + ": vertex " + std::to_string(v.idx()) +
                          " has a non-finite position");
    if (options.scale != 1.0) mesh.set_point(v, p * options.scale);
  }
  return mesh;
}

namespace {

// Binary PLY in the layout OpenMesh's writer gives it (the same bytes): x y z, then nx ny nz, u v
// and red green blue as floats when written, then each face as a uchar count and int indices in
// OpenMesh's face-vertex order. Built in memory and written with one call, without OpenMesh's
// per-value stream writes and global lock. Only for meshes without deleted elements (false
// otherwise: the caller uses OpenMesh's writer).
bool direct_ply_applies(const Mesh& mesh) {
  if constexpr (std::endian::native != std::endian::little) return false;
  if (mesh.has_vertex_status())
    for (auto v : mesh.vertices())
      if (mesh.status(v).deleted()) return false;
  if (mesh.has_face_status())
    for (auto f : mesh.faces())
      if (mesh.status(f).deleted()) return false;
  return true;
}

// The header of a binary PLY with these vertex properties and triangle-list faces.
std::string ply_binary_header(size_t vertices, size_t faces, bool normals, bool texcoords,
                              bool colors) {
  std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex ";
  header += std::to_string(vertices);
  header += "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (texcoords) header += "property float u\nproperty float v\n";
  if (colors) header += "property float red\nproperty float green\nproperty float blue\n";
  header += "element face ";
  header += std::to_string(faces);
  header += "\nproperty list uchar int vertex_indices\nend_header\n";
  return header;
}

std::string ply_binary_bytes(const Mesh& mesh, bool normals, bool texcoords, bool colors) {
  const std::string header =
      ply_binary_header(mesh.n_vertices(), mesh.n_faces(), normals, texcoords, colors);
  const size_t floats = 3 + (normals ? 3 : 0) + (texcoords ? 2 : 0) + (colors ? 3 : 0);
  // Faces' vertex indices gathered first (one walk around each face).
  std::vector<int32_t> corners;
  std::vector<uint8_t> valences;
  corners.reserve(3 * mesh.n_faces());
  valences.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    const size_t before = corners.size();
    for (auto v : mesh.fv_range(f)) corners.push_back(v.idx());
    valences.push_back(static_cast<uint8_t>(corners.size() - before));
  }
  std::string out;
  out.resize(header.size() + mesh.n_vertices() * floats * 4 + valences.size() + 4 * corners.size());
  char* p = out.data();
  std::memcpy(p, header.data(), header.size());
  p += header.size();
  const auto put = [&p](float v) {
    std::memcpy(p, &v, 4);
    p += 4;
  };
  for (auto v : mesh.vertices()) {
    const Mesh::Point& x = mesh.point(v);
    put(static_cast<float>(x[0]));
    put(static_cast<float>(x[1]));
    put(static_cast<float>(x[2]));
    if (normals) {
      const Mesh::Normal& n = mesh.normal(v);
      put(static_cast<float>(n[0]));
      put(static_cast<float>(n[1]));
      put(static_cast<float>(n[2]));
    }
    if (texcoords) {
      const Mesh::TexCoord2D& t = mesh.texcoord2D(v);
      put(static_cast<float>(t[0]));
      put(static_cast<float>(t[1]));
    }
    if (colors) {
      const Mesh::Color& c = mesh.color(v);
      put(c[0]);
      put(c[1]);
      put(c[2]);
    }
  }
  const int32_t* corner = corners.data();
  for (const uint8_t valence : valences) {
    *p++ = static_cast<char>(valence);
    std::memcpy(p, corner, 4 * size_t{valence});
    p += 4 * size_t{valence};
    corner += valence;
  }
  return out;
}

std::string ply_binary_bytes(const MeshArrays& a, bool normals, bool texcoords, bool colors) {
  const std::string header =
      ply_binary_header(a.vertex_count, a.triangle_count, normals, texcoords, colors);
  const size_t floats = 3 + (normals ? 3 : 0) + (texcoords ? 2 : 0) + (colors ? 3 : 0);
  std::string out;
  out.resize(header.size() + a.vertex_count * floats * 4 + a.triangle_count * 13);
  char* p = out.data();
  std::memcpy(p, header.data(), header.size());
  p += header.size();
  const auto put = [&p](const float* v, size_t count) {
    std::memcpy(p, v, 4 * count);
    p += 4 * count;
  };
  for (size_t i = 0; i < a.vertex_count; ++i) {
    put(a.positions_mm + 3 * i, 3);
    if (normals) put(a.normals + 3 * i, 3);
    if (texcoords) put(a.texcoords + 2 * i, 2);
    if (colors) {
      const float g[3] = {a.grey[i], a.grey[i], a.grey[i]};
      put(g, 3);
    }
  }
  for (size_t t = 0; t < a.triangle_count; ++t) {
    *p++ = 3;
    std::memcpy(p, a.indices + 3 * t, 12);  // < 2^31 (checked): the same bytes as int32
    p += 12;
  }
  return out;
}

}  // namespace

Status write_mesh_arrays(const fs::path& path, const MeshArrays& arrays,
                         const MeshWriteOptions& options) {
  if (lower_extension(path) != ".ply")
    return unsupported(path.string() + ": mesh arrays are written as binary PLY only (use .ply)");
  if (!options.binary || options.openmesh_writer)
    return unsupported(path.string() + ": mesh arrays are written as binary PLY by gvkit only");
  if constexpr (std::endian::native != std::endian::little)
    return unsupported(path.string() + ": binary PLY from arrays needs a little-endian machine");
  if (arrays.vertex_count > 0 && !arrays.positions_mm)
    return invalid_argument(path.string() + ": mesh arrays without positions");
  if (arrays.triangle_count > 0 && !arrays.indices)
    return invalid_argument(path.string() + ": mesh arrays without triangle indices");
  if (arrays.vertex_count > static_cast<size_t>(INT32_MAX))
    return invalid_argument(path.string() + ": too many vertices for PLY int indices");
  for (size_t i = 0; i < 3 * arrays.triangle_count; ++i)
    if (arrays.indices[i] >= arrays.vertex_count)
      return invalid_argument(path.string() + ": triangle " + std::to_string(i / 3) +
                              " names vertex " + std::to_string(arrays.indices[i]) + " of " +
                              std::to_string(arrays.vertex_count));
  const bool normals = options.vertex_normals && arrays.normals;
  const bool texcoords = options.vertex_texcoords && arrays.texcoords;
  const bool colors = options.vertex_colors && arrays.grey;
  return write_file_atomically(path, ply_binary_bytes(arrays, normals, texcoords, colors));
}

Status write_mesh(const fs::path& path, const Mesh& mesh, const MeshWriteOptions& options) {
  silence_openmesh_logs();
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  if (ext == ".ply" && options.binary && !options.openmesh_writer && direct_ply_applies(mesh)) {
    const bool normals = options.vertex_normals && mesh.has_vertex_normals();
    const bool texcoords = options.vertex_texcoords && mesh.has_vertex_texcoords2D();
    const bool colors = options.vertex_colors && mesh.has_vertex_colors();
    return write_file_atomically(path, ply_binary_bytes(mesh, normals, texcoords, colors));
  }
  OpenMesh::IO::Options io_options;
  if (options.binary && ext == ".ply") io_options += OpenMesh::IO::Options::Binary;
  // OBJ has no standard per-vertex colour; colours are written to PLY only.
  if (options.vertex_colors && mesh.has_vertex_colors() && ext == ".ply") {
    io_options += OpenMesh::IO::Options::VertexColor;
    io_options += OpenMesh::IO::Options::ColorFloat;
  }
  if (options.vertex_texcoords && mesh.has_vertex_texcoords2D())
    io_options += OpenMesh::IO::Options::VertexTexCoord;
  if (options.vertex_normals && mesh.has_vertex_normals())
    io_options += OpenMesh::IO::Options::VertexNormal;
  return write_via_temp_file(path, [&](const fs::path& temp) -> Status {
    bool ok = false;
    try {
      std::lock_guard<std::mutex> lock(openmesh_io_mutex());
      ok = OpenMesh::IO::write_mesh(mesh, temp.string(), io_options);
    } catch (const std::exception& e) {
      return io_error(path.string() + ": cannot write mesh: " + e.what());
    }
    if (!ok) return io_error(path.string() + ": cannot write mesh");
    return Status::ok();
  });
}

}  // namespace gvkit
