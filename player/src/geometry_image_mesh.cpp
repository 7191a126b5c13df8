#include "gvkit/player/geometry_image_mesh.hpp"

#include <array>
#include <cmath>
#include <memory>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gvkit::player {
namespace {

float distance2(const cv::Vec3f& a, const cv::Vec3f& b) {
  const cv::Vec3f d = a - b;
  return d.dot(d);
}

}  // namespace

Status GeometryImageMeshOptions::check() const {
  if (!(max_edge_mm >= 0.0) || !std::isfinite(max_edge_mm))
    return invalid_argument("max_edge_mm must be >= 0 (0 = keep every triangle)");
  if (stride < 1 || stride > 16) return invalid_argument("mesh stride must be in 1..16");
  return Status::ok();
}

MeshBuffers mesh_buffers_from_geometry_image(const GeometryImage& image,
                                             const GeometryImageMeshOptions& options) {
  GVKIT_CHECK(image.check().is_ok(), image.check().message());
  GVKIT_CHECK(options.check().is_ok(), options.check().message());
  const int w = image.xyz_mm.cols, h = image.xyz_mm.rows;
  MeshBuffers out;
  out.width = w;
  out.height = h;
  const bool has_grey = !image.texture.empty();

  // Vertex numbering: domain pixels with finite xyz, row-major.
  const int step = options.stride;
  std::vector<int32_t> vertex_of(static_cast<size_t>(w) * h, -1);
  // Room for every sampled pixel and two triangles per quad (no regrowth and copy).
  const size_t samples = static_cast<size_t>((w + step - 1) / step) * ((h + step - 1) / step);
  out.pixel_index.reserve(samples);
  out.positions_mm.reserve(3 * samples);
  out.texcoords.reserve(2 * samples);
  if (has_grey) out.grey.reserve(samples);
  out.indices.reserve(6 * samples);
  for (int y = 0; y < h; y += step) {
    const cv::Vec3f* p = image.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* m = image.domain_mask.ptr<uint8_t>(y);
    const float* t = has_grey ? image.texture.ptr<float>(y) : nullptr;
    for (int x = 0; x < w; x += step) {
      if (!m[x] || !std::isfinite(p[x][0]) || !std::isfinite(p[x][1]) || !std::isfinite(p[x][2]))
        continue;
      vertex_of[static_cast<size_t>(y) * w + x] = static_cast<int32_t>(out.pixel_index.size());
      out.pixel_index.push_back(y * w + x);
      out.positions_mm.insert(out.positions_mm.end(), {p[x][0], p[x][1], p[x][2]});
      out.texcoords.insert(out.texcoords.end(), {(x + 0.5f) / static_cast<float>(w),
                                                 (y + 0.5f) / static_cast<float>(h)});
      if (has_grey) out.grey.push_back(std::clamp(t[x], 0.0f, 1.0f));
    }
  }

  const float max_edge2 = static_cast<float>(options.max_edge_mm * options.max_edge_mm);
  auto add_triangle = [&](const std::array<int32_t, 3>& v, const std::array<cv::Vec3f, 3>& p) {
    if (max_edge2 > 0 && (distance2(p[0], p[1]) > max_edge2 || distance2(p[1], p[2]) > max_edge2 ||
                          distance2(p[2], p[0]) > max_edge2))
      return;
    for (int32_t i : v) out.indices.push_back(static_cast<uint32_t>(i));
  };

  for (int y = 0; y + step < h; y += step) {
    const cv::Vec3f* row0 = image.xyz_mm.ptr<cv::Vec3f>(y);
    const cv::Vec3f* row1 = image.xyz_mm.ptr<cv::Vec3f>(y + step);
    const int32_t* v0 = &vertex_of[static_cast<size_t>(y) * w];
    const int32_t* v1 = &vertex_of[static_cast<size_t>(y + step) * w];
    for (int x = 0; x + step < w; x += step) {
      // Corners in the cyclic order that gives the documented winding: a (x,y), c (x,y+1),
      // d (x+1,y+1), b (x+1,y) (in steps of `step` pixels).
      const int x1 = x + step;
      const std::array<int32_t, 4> v = {v0[x], v1[x], v1[x1], v0[x1]};
      const std::array<cv::Vec3f, 4> p = {row0[x], row1[x], row1[x1], row0[x1]};
      const int present = (v[0] >= 0) + (v[1] >= 0) + (v[2] >= 0) + (v[3] >= 0);
      if (present == 4) {
        if (distance2(p[0], p[2]) <= distance2(p[1], p[3])) {  // split along a-d
          add_triangle({v[0], v[1], v[2]}, {p[0], p[1], p[2]});
          add_triangle({v[0], v[2], v[3]}, {p[0], p[2], p[3]});
        } else {  // split along c-b
          add_triangle({v[0], v[1], v[3]}, {p[0], p[1], p[3]});
          add_triangle({v[1], v[2], v[3]}, {p[1], p[2], p[3]});
        }
      } else if (present == 3 && options.partial_quads) {
        std::array<int32_t, 3> tv{};
        std::array<cv::Vec3f, 3> tp;
        int k = 0;
        for (int i = 0; i < 4; ++i)
          if (v[i] >= 0) {
            tv[k] = v[i];
            tp[k++] = p[i];
          }
        add_triangle(tv, tp);
      }
    }
  }

  // Area-weighted vertex normals: the unnormalised face normal is twice the area times the unit
  // normal, so summing it weights by area.
  const size_t n = out.vertex_count();
  std::vector<double> acc(3 * n, 0.0);
  const float* pos = out.positions_mm.data();
  for (size_t t = 0; t < out.indices.size(); t += 3) {
    const uint32_t i0 = out.indices[t], i1 = out.indices[t + 1], i2 = out.indices[t + 2];
    const cv::Vec3d a(pos[3 * i0], pos[3 * i0 + 1], pos[3 * i0 + 2]);
    const cv::Vec3d b(pos[3 * i1], pos[3 * i1 + 1], pos[3 * i1 + 2]);
    const cv::Vec3d c(pos[3 * i2], pos[3 * i2 + 1], pos[3 * i2 + 2]);
    const cv::Vec3d fn = (b - a).cross(c - a);
    for (uint32_t i : {i0, i1, i2})
      for (int k = 0; k < 3; ++k) acc[3 * i + k] += fn[k];
  }
  out.normals.resize(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const double len = std::sqrt(acc[3 * i] * acc[3 * i] + acc[3 * i + 1] * acc[3 * i + 1] +
                                 acc[3 * i + 2] * acc[3 * i + 2]);
    for (int k = 0; k < 3; ++k)
      out.normals[3 * i + k] = len > 0 ? static_cast<float>(acc[3 * i + k] / len) : 0.0f;
  }
  return out;
}

namespace {

// Whether the link edges e[0, k) of one vertex (the edges of its triangles opposite it, in the
// triangles' winding) chain into one path or one cycle, as mesh_buffers_manifold defines it; the
// plain O(k^2) definition.
bool link_is_one_fan_reference(const std::array<uint32_t, 2>* e, size_t k) {
  // A repeated start is a directed edge v -> start in two triangles, a repeated end one
  // end -> v in two; then the link is one path or cycle iff a walk from the path's start (or,
  // with no start, from any edge) follows all k edges.
  size_t begin = 0, starts = 0;
  for (size_t i = 0; i < k; ++i) {
    bool is_end_of_another = false;
    for (size_t j = 0; j < k; ++j) {
      if (j == i) continue;
      if (e[j][0] == e[i][0] || e[j][1] == e[i][1]) return false;
      if (e[j][1] == e[i][0]) is_end_of_another = true;
    }
    if (!is_end_of_another) {
      begin = i;
      ++starts;
    }
  }
  if (starts > 1) return false;
  size_t walked = 1;
  for (uint32_t at = e[begin][1]; walked < k; ++walked) {
    size_t next = k;
    for (size_t j = 0; j < k; ++j)
      if (e[j][0] == at) next = j;
    if (next == k || next == begin) break;
    at = e[next][1];
  }
  return walked == k;
}

// The same for k <= 8 with the comparisons of one edge against all eight lanes at once (SSE2:
// two 4-lane compares; bit j of a mask is edge j). An edge never matches itself (a triangle has
// three different vertices), so a start or end shared with another edge shows as a second bit.
constexpr size_t kLinkLanes = 8;
struct Lanes {
#if defined(__SSE2__)
  __m128i low, high;
  explicit Lanes(const uint32_t* v)
      : low(_mm_loadu_si128(reinterpret_cast<const __m128i*>(v))),
        high(_mm_loadu_si128(reinterpret_cast<const __m128i*>(v + 4))) {}
  uint32_t equal(uint32_t value) const {
    const __m128i x = _mm_set1_epi32(static_cast<int>(value));
    return static_cast<uint32_t>(
        _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(low, x))) |
        (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(high, x))) << 4));
  }
#else
  const uint32_t* v;
  explicit Lanes(const uint32_t* values) : v(values) {}
  uint32_t equal(uint32_t value) const {
    uint32_t mask = 0;
    for (size_t j = 0; j < kLinkLanes; ++j) mask |= static_cast<uint32_t>(v[j] == value) << j;
    return mask;
  }
#endif
};
bool link_is_one_fan_small(const std::array<uint32_t, 2>* e, size_t k) {
  uint32_t start_values[kLinkLanes], end_values[kLinkLanes];
  for (size_t j = 0; j < kLinkLanes; ++j) {
    start_values[j] = j < k ? e[j][0] : e[0][0];  // padding lanes repeat edge 0; masked off
    end_values[j] = j < k ? e[j][1] : e[0][1];
  }
  const Lanes starts(start_values), ends(end_values);
  const uint32_t valid = (1u << k) - 1;
  uint8_t next[kLinkLanes];
  size_t begin = 0, start_count = 0;
  for (size_t i = 0; i < k; ++i) {
    const uint32_t same = (starts.equal(start_values[i]) | ends.equal(end_values[i])) & valid;
    if (same != (1u << i)) return false;
    if ((ends.equal(start_values[i]) & valid) == 0) {  // no edge ends where this one starts
      begin = i;
      ++start_count;
    }
    const uint32_t successor = starts.equal(end_values[i]) & valid;
    next[i] = static_cast<uint8_t>(successor ? __builtin_ctz(successor) : k);
  }
  if (start_count > 1) return false;
  size_t walked = 1;
  for (size_t at = next[begin]; walked < k && at != k && at != begin; at = next[at]) ++walked;
  return walked == k;
}

// The link edges of every vertex, gathered in compressed rows; false (nothing checked) when an
// index is out of range or a triangle repeats a vertex.
template <class LinkCheck>
bool every_link_one_fan(const MeshBuffers& buffers, const LinkCheck& check) {
  const size_t n = buffers.vertex_count(), triangles = buffers.triangle_count();
  const uint32_t* idx = buffers.indices.data();
  std::vector<uint32_t> offset(n + 1, 0);
  for (size_t k = 0; k < 3 * triangles; ++k) {
    if (idx[k] >= n) return false;
    ++offset[idx[k] + 1];
  }
  for (size_t v = 0; v < n; ++v) offset[v + 1] += offset[v];
  // (Every slot is written below: no zero fill of the 24 bytes per triangle.)
  const std::unique_ptr<std::array<uint32_t, 2>[]> link(new std::array<uint32_t, 2>[3 * triangles]);
  std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
  for (size_t t = 0; t < triangles; ++t) {
    const uint32_t a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
    if (a == b || b == c || c == a) return false;
    link[fill[a]++] = {b, c};
    link[fill[b]++] = {c, a};
    link[fill[c]++] = {a, b};
  }
  for (size_t v = 0; v < n; ++v) {
    const size_t k = offset[v + 1] - offset[v];
    if (k > 0 && !check(link.get() + offset[v], k)) return false;
  }
  return true;
}

}  // namespace

bool mesh_buffers_manifold(const MeshBuffers& buffers) {
  return every_link_one_fan(buffers, [](const std::array<uint32_t, 2>* e, size_t k) {
    return k <= kLinkLanes ? link_is_one_fan_small(e, k) : link_is_one_fan_reference(e, k);
  });
}

bool mesh_buffers_manifold_reference(const MeshBuffers& buffers) {
  return every_link_one_fan(buffers, link_is_one_fan_reference);
}

MeshArrays mesh_arrays(const MeshBuffers& buffers) {
  MeshArrays a;
  a.vertex_count = buffers.vertex_count();
  a.positions_mm = buffers.positions_mm.data();
  a.normals = buffers.normals.size() == 3 * a.vertex_count ? buffers.normals.data() : nullptr;
  a.texcoords = buffers.texcoords.size() == 2 * a.vertex_count ? buffers.texcoords.data() : nullptr;
  a.grey = buffers.grey.empty() ? nullptr : buffers.grey.data();
  a.triangle_count = buffers.triangle_count();
  a.indices = buffers.indices.data();
  return a;
}

Mesh mesh_from_buffers(const MeshBuffers& buffers, int* dropped_faces) {
  Mesh mesh;
  mesh.request_vertex_normals();
  mesh.request_vertex_texcoords2D();
  const bool grey = !buffers.grey.empty();
  if (grey) mesh.request_vertex_colors();
  const size_t n = buffers.vertex_count();
  // Room for every element at once (a disc with b holes has vertices + faces - 1 + b edges;
  // the slack covers many holes), instead of the kernel's arrays and properties growing by
  // doubling.
  const size_t faces = buffers.triangle_count();
  mesh.reserve(n, n + faces + n / 8 + 64, faces);
  std::vector<Mesh::VertexHandle> handles(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &buffers.positions_mm[3 * i];
    const float* nr = &buffers.normals[3 * i];
    handles[i] = mesh.add_vertex(Mesh::Point(p[0], p[1], p[2]));
    mesh.set_normal(handles[i], Mesh::Normal(nr[0], nr[1], nr[2]));
    mesh.set_texcoord2D(handles[i],
                        Mesh::TexCoord2D(buffers.texcoords[2 * i], buffers.texcoords[2 * i + 1]));
    if (grey) {
      const float g = buffers.grey[i];
      mesh.set_color(handles[i], Mesh::Color(g, g, g, 1.0f));
    }
  }
  int dropped = 0;
  for (size_t t = 0; t < buffers.indices.size(); t += 3) {
    const auto f = mesh.add_face(handles[buffers.indices[t]], handles[buffers.indices[t + 1]],
                                 handles[buffers.indices[t + 2]]);
    if (!f.is_valid()) ++dropped;
  }
  if (dropped_faces) *dropped_faces = dropped;
  return mesh;
}

Result<GeometryImage> geometry_image_from_range_scan(const RangeScan& scan) {
  GVKIT_RETURN_IF_ERROR(scan.check());
  GeometryImage image;
  image.xyz_mm = scan.xyz_mm.clone();
  image.xyz_mm.setTo(cv::Scalar::all(0), scan.valid == 0);
  // NaNs that slipped through a valid pixel would fail check(); the scan's check() rules them out.
  image.domain_mask = scan.valid.clone();
  if (!scan.texture.empty()) image.texture = scan.texture.clone();
  image.index = scan.index;
  image.timestamp = scan.timestamp;
  return image;
}

}  // namespace gvkit::player
