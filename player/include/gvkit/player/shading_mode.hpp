#pragma once
// How the player colours a surface.

#include <string>

#include "gvkit/core/status.hpp"

namespace gvkit::player {

enum class ShadingMode {
  kLit,        // uniform colour, headlight + key light, two-sided
  kTexture,    // the geometry image's grey texture (lit when the frame has none)
  kNormals,    // world-space normal as RGB (n * 0.5 + 0.5)
  kWireframe,  // lit surface with the triangle edges on top
  kError,      // per-vertex distance to a reference (mm), Turbo colour scale
};

// "lit", "texture", "normals", "wireframe", "error"; fails naming the accepted values.
Result<ShadingMode> parse_shading_mode(const std::string& name);
const char* shading_mode_name(ShadingMode mode);

}  // namespace gvkit::player
