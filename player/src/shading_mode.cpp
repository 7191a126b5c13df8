#include "gvkit/player/shading_mode.hpp"

namespace gvkit::player {

Result<ShadingMode> parse_shading_mode(const std::string& name) {
  for (ShadingMode m : {ShadingMode::kLit, ShadingMode::kTexture, ShadingMode::kNormals,
                        ShadingMode::kWireframe, ShadingMode::kError})
    if (name == shading_mode_name(m)) return m;
  return invalid_argument("unknown shading '" + name +
                          "' (use lit, texture, normals, wireframe or error)");
}

const char* shading_mode_name(ShadingMode mode) {
  switch (mode) {
    case ShadingMode::kLit:
      return "lit";
    case ShadingMode::kTexture:
      return "texture";
    case ShadingMode::kNormals:
      return "normals";
    case ShadingMode::kWireframe:
      return "wireframe";
    case ShadingMode::kError:
      return "error";
  }
  return "?";
}

}  // namespace gvkit::player
