#include "gvkit/core/mesh_io.hpp"

// MeshIO must be included before any OpenMesh kernel header that mesh.hpp pulls in.
#include <OpenMesh/Core/IO/MeshIO.hh>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstring>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/shortest_float.hpp"
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

// gvkit's serializers write meshes without deleted elements (with them: OpenMesh's writer).
bool no_deleted_elements(const Mesh& mesh) {
  if (mesh.has_vertex_status())
    for (auto v : mesh.vertices())
      if (mesh.status(v).deleted()) return false;
  if (mesh.has_face_status())
    for (auto f : mesh.faces())
      if (mesh.status(f).deleted()) return false;
  return true;
}

// The header of a PLY (binary little endian or ASCII) with these vertex properties and
// triangle-list faces.
std::string ply_header(bool binary, size_t vertices, size_t faces, bool normals, bool texcoords,
                       bool colors) {
  std::string header = binary ? "ply\nformat binary_little_endian 1.0\nelement vertex "
                              : "ply\nformat ascii 1.0\nelement vertex ";
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

// The colour of vertex i (r, g, b) of arrays with grey or colours.
const float* vertex_color(const MeshArrays& a, size_t i, float (&grey)[3]) {
  if (!a.grey) return a.colors + 3 * i;
  grey[0] = grey[1] = grey[2] = a.grey[i];
  return grey;
}

// Binary PLY in the layout OpenMesh's writer gives it (the same bytes): x y z, then nx ny nz, u v
// and red green blue as floats when written, then each face as a uchar count and int indices in
// OpenMesh's face-vertex order. Built in memory and written with one call, without OpenMesh's
// per-value stream writes and global lock.
std::string ply_binary_bytes(const MeshArrays& a, bool normals, bool texcoords, bool colors) {
  const std::string header =
      ply_header(true, a.vertex_count, a.triangle_count, normals, texcoords, colors);
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
  float grey[3];
  for (size_t i = 0; i < a.vertex_count; ++i) {
    put(a.positions_mm + 3 * i, 3);
    if (normals) put(a.normals + 3 * i, 3);
    if (texcoords) put(a.texcoords + 2 * i, 2);
    if (colors) put(vertex_color(a, i, grey), 3);
  }
  for (size_t t = 0; t < a.triangle_count; ++t) {
    *p++ = 3;
    std::memcpy(p, a.indices + 3 * t, 12);  // < 2^31 (checked): the same bytes as int32
    p += 12;
  }
  return out;
}

// The texts of recently written floats (write_shortest_float's), 1024 slots addressed by a hash
// of the float's bits: a column of texture coordinates (u takes one value per image column, v one
// per row) or of grey levels written as r = g = b repeats a few values, and copying a text is
// cheaper than finding it again. A slot holds the last value that hashed to it.
class FloatTexts {
 public:
  // As write_shortest_float(out, v) (kShortestFloatRoom bytes at out).
  char* write(char* out, float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    Slot& slot = slots_[(bits * 0x9E3779B1u) >> (32 - kSlotBits)];
    if (slot.length != 0 && slot.bits == bits) {
      std::memcpy(out, slot.text, sizeof slot.text);
      return out + slot.length;
    }
    char* end = write_shortest_float(out, v);
    slot.bits = bits;
    slot.length = static_cast<uint8_t>(end - out);  // 1..15
    std::memcpy(slot.text, out, sizeof slot.text);
    return end;
  }

 private:
  static constexpr int kSlotBits = 10;
  struct Slot {
    uint32_t bits = 0;
    uint8_t length = 0;  // 0: empty
    char text[16];
  };
  std::vector<Slot> slots_ = std::vector<Slot>(size_t{1} << kSlotBits);
};

// Text output with numbers in their shortest exact form (std::to_chars's text; floats through
// write_shortest_float, the same characters faster), formatted into a small
// staging buffer that is appended to the reserved text 4 KiB at a time (no per-value string
// append, no zero fill of the whole text).
class TextOut {
 public:
  explicit TextOut(size_t reserve) { out_.reserve(reserve); }
  TextOut& text(std::string_view s) {
    if (s.size() > kStage - used_) {
      flush();
      if (s.size() > kStage) {
        out_.append(s);
        return *this;
      }
    }
    std::memcpy(stage_ + used_, s.data(), s.size());
    used_ += s.size();
    return *this;
  }
  TextOut& text(char c) {
    room(1);
    stage_[used_++] = c;
    return *this;
  }
  TextOut& number(float v) {
    room(kMaxNumberChars);
    used_ = static_cast<size_t>(write_shortest_float(stage_ + used_, v) - stage_);
    return *this;
  }
  TextOut& number(uint64_t v) {
    room(kMaxNumberChars);
    used_ = static_cast<size_t>(std::to_chars(stage_ + used_, stage_ + kStage, v).ptr - stage_);
    return *this;
  }
  // " a b c" for count floats at v.
  TextOut& numbers(const float* v, int count) {
    for (int k = 0; k < count; ++k) text(' ').number(v[k]);
    return *this;
  }
  // The same through a cache of texts (for columns of few distinct values).
  TextOut& numbers(const float* v, int count, FloatTexts& cache) {
    for (int k = 0; k < count; ++k) {
      room(1 + kMaxNumberChars);
      stage_[used_++] = ' ';
      used_ = static_cast<size_t>(cache.write(stage_ + used_, v[k]) - stage_);
    }
    return *this;
  }
  std::string take() {
    flush();
    return std::move(out_);
  }

 private:
  // Room for a float (kShortestFloatRoom) or a uint64 (20 digits).
  static constexpr size_t kMaxNumberChars = 32;
  static_assert(kShortestFloatRoom <= kMaxNumberChars);
  static constexpr size_t kStage = 4096;
  void room(size_t n) {
    if (used_ + n > kStage) flush();
  }
  void flush() {
    out_.append(stage_, used_);
    used_ = 0;
  }
  std::string out_;
  char stage_[kStage];
  size_t used_ = 0;  // characters in stage_, after out_'s
};

std::string ply_ascii_text(const MeshArrays& a, bool normals, bool texcoords, bool colors) {
  TextOut out(a.vertex_count * 120 + a.triangle_count * 24);
  out.text(ply_header(false, a.vertex_count, a.triangle_count, normals, texcoords, colors));
  float grey[3];
  FloatTexts texcoord_texts, color_texts;
  for (size_t i = 0; i < a.vertex_count; ++i) {
    out.number(a.positions_mm[3 * i]).numbers(a.positions_mm + 3 * i + 1, 2);
    if (normals) out.numbers(a.normals + 3 * i, 3);
    if (texcoords) out.numbers(a.texcoords + 2 * i, 2, texcoord_texts);
    if (colors) out.numbers(vertex_color(a, i, grey), 3, color_texts);
    out.text('\n');
  }
  for (size_t t = 0; t < a.triangle_count; ++t) {
    out.text('3');
    for (int k = 0; k < 3; ++k) out.text(' ').number(uint64_t{a.indices[3 * t + k]});
    out.text('\n');
  }
  return out.take();
}

// OBJ: v, then vt and vn (one per vertex) when written, then f with 1-based v/vt/vn indices.
std::string obj_text(const MeshArrays& a, bool normals, bool texcoords) {
  // Reserved: the face lines at most (every index with the digits of the largest), the vertex
  // lines at 12 characters a float. An estimate that falls short doubles the text while it is
  // written, past glibc's mmap threshold for a 320x320 frame: fresh pages to fault in per frame.
  size_t digits = 1;
  for (size_t n = a.vertex_count; n >= 10; n /= 10) ++digits;
  const size_t per_corner = 1 + digits * (1 + texcoords + normals) + (normals ? 2 : texcoords);
  const size_t per_vertex =
      (2 + 3 * 13) + (texcoords ? 3 + 2 * 13 : 0) + (normals ? 3 + 3 * 13 : 0);
  TextOut out(64 + a.vertex_count * per_vertex + a.triangle_count * (2 + 3 * per_corner));
  out.text("# ").number(uint64_t{a.vertex_count}).text(" vertices, ");
  out.number(uint64_t{a.triangle_count}).text(" faces\n");
  for (size_t i = 0; i < a.vertex_count; ++i)
    out.text('v').numbers(a.positions_mm + 3 * i, 3).text('\n');
  if (texcoords) {
    FloatTexts texcoord_texts;
    for (size_t i = 0; i < a.vertex_count; ++i)
      out.text("vt").numbers(a.texcoords + 2 * i, 2, texcoord_texts).text('\n');
  }
  if (normals)
    for (size_t i = 0; i < a.vertex_count; ++i)
      out.text("vn").numbers(a.normals + 3 * i, 3).text('\n');
  for (size_t t = 0; t < a.triangle_count; ++t) {
    out.text('f');
    for (int k = 0; k < 3; ++k) {
      // The 1-based index, formatted once for v, vt and vn.
      char digits[24];
      const std::string_view v(
          digits,
          static_cast<size_t>(
              std::to_chars(digits, digits + sizeof digits, a.indices[3 * t + k] + 1ull).ptr -
              digits));
      out.text(' ').text(v);
      if (texcoords) out.text('/').text(v);
      if (normals) out.text(texcoords ? "/" : "//").text(v);
    }
    out.text('\n');
  }
  return out.take();
}

// A Mesh's vertices and faces as float arrays (what gvkit's serializers write), faces in
// OpenMesh's face-vertex order.
struct MeshArrayStorage {
  std::vector<float> positions, normals, texcoords, colors;
  std::vector<uint32_t> indices;
  MeshArrays view() const {
    MeshArrays a;
    a.vertex_count = positions.size() / 3;
    a.positions_mm = positions.data();
    a.normals = normals.empty() ? nullptr : normals.data();
    a.texcoords = texcoords.empty() ? nullptr : texcoords.data();
    a.colors = colors.empty() ? nullptr : colors.data();
    a.triangle_count = indices.size() / 3;
    a.indices = indices.data();
    return a;
  }
};

MeshArrayStorage mesh_array_storage(const Mesh& mesh, bool normals, bool texcoords, bool colors) {
  MeshArrayStorage s;
  const size_t n = mesh.n_vertices();
  s.positions.reserve(3 * n);
  for (auto v : mesh.vertices()) {
    const Mesh::Point& p = mesh.point(v);
    s.positions.insert(s.positions.end(), {static_cast<float>(p[0]), static_cast<float>(p[1]),
                                           static_cast<float>(p[2])});
    if (normals) {
      const Mesh::Normal& q = mesh.normal(v);
      s.normals.insert(s.normals.end(), {static_cast<float>(q[0]), static_cast<float>(q[1]),
                                         static_cast<float>(q[2])});
    }
    if (texcoords) {
      const Mesh::TexCoord2D& t = mesh.texcoord2D(v);
      s.texcoords.insert(s.texcoords.end(), {static_cast<float>(t[0]), static_cast<float>(t[1])});
    }
    if (colors) {
      const Mesh::Color& c = mesh.color(v);
      s.colors.insert(s.colors.end(), {c[0], c[1], c[2]});
    }
  }
  s.indices.reserve(3 * mesh.n_faces());
  for (auto f : mesh.faces())
    for (auto v : mesh.fv_range(f)) s.indices.push_back(static_cast<uint32_t>(v.idx()));
  return s;
}

// The file of `arrays` in the format of `ext` (".ply" binary or ASCII by options, ".obj").
std::string mesh_file_bytes(const std::string& ext, const MeshArrays& a,
                            const MeshWriteOptions& options) {
  const bool normals = options.vertex_normals && a.normals;
  const bool texcoords = options.vertex_texcoords && a.texcoords;
  const bool colors = options.vertex_colors && (a.grey || a.colors);
  if (ext == ".obj") return obj_text(a, normals, texcoords);
  return options.binary ? ply_binary_bytes(a, normals, texcoords, colors)
                        : ply_ascii_text(a, normals, texcoords, colors);
}

}  // namespace

Status write_mesh_arrays(const fs::path& path, const MeshArrays& arrays,
                         const MeshWriteOptions& options) {
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  if (options.openmesh_writer)
    return unsupported(path.string() + ": mesh arrays are written by gvkit's serializers only");
  if constexpr (std::endian::native != std::endian::little)
    if (ext == ".ply" && options.binary)
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
  return write_file_atomically(path, mesh_file_bytes(ext, arrays, options));
}

Status write_mesh(const fs::path& path, const Mesh& mesh, const MeshWriteOptions& options) {
  silence_openmesh_logs();
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  const bool little_endian = std::endian::native == std::endian::little;
  if (!options.openmesh_writer && no_deleted_elements(mesh) &&
      (little_endian || ext == ".obj" || !options.binary)) {
    const bool normals = options.vertex_normals && mesh.has_vertex_normals();
    const bool texcoords = options.vertex_texcoords && mesh.has_vertex_texcoords2D();
    const bool colors = options.vertex_colors && mesh.has_vertex_colors();
    const MeshArrayStorage storage = mesh_array_storage(mesh, normals, texcoords, colors);
    return write_file_atomically(path, mesh_file_bytes(ext, storage.view(), options));
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
