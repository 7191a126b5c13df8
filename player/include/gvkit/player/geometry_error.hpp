#pragma once
// Error of a geometry video frame against a reference on the same domain grid (e.g. decoded
// against original): per-vertex distances for the heat map, and the summary figures of
// DESIGN.md section 6 (RMS, max, geometry PSNR over domain pixels).

#include <cstdint>
#include <vector>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {

// Distance (mm) from each vertex of mesh to the reference xyz at the vertex's pixel; NaN where
// that pixel is outside the reference's domain. Fails when the reference's size differs from
// the mesh's source image.
Result<std::vector<float>> vertex_errors_mm(const MeshBuffers& mesh,
                                            const GeometryImage& reference);

struct GeometryErrorStats {
  int64_t pixels = 0;  // pixels inside both domains
  double rms_mm = 0, max_mm = 0;
  double peak_mm = 0;  // PSNR peak: bounding-box diagonal
  double psnr_db = 0;  // 20 log10(peak / rms); +inf when rms is 0
};

// Over pixels inside both domains. peak_mm > 0 is used as the PSNR peak (DESIGN.md: the
// sequence's bounding-box diagonal); 0 takes the reference frame's own box diagonal. Fails on
// different sizes or when no pixel is in both domains.
Result<GeometryErrorStats> geometry_error(const GeometryImage& image,
                                          const GeometryImage& reference, double peak_mm = 0);

}  // namespace gvkit::player
