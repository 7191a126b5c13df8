#include "gvkit/core/mesh_io.hpp"

// MeshIO must be included before any OpenMesh kernel header that mesh.hpp pulls in.
#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <cctype>
#include <mutex>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/mesh.hpp"
#include "ply_header.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

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

Status write_mesh(const fs::path& path, const Mesh& mesh, const MeshWriteOptions& options) {
  silence_openmesh_logs();
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
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
