#include "surface_error_json.hpp"

namespace gvkit::tools {

nlohmann::json surface_error_json(const codec::SurfaceError& e) {
  return {{"normal_mean_deg", e.normal_mean_deg()},
          {"normal_p95_deg", e.normal_p95_deg()},
          {"normal_max_deg", e.normal_max_deg},
          {"hausdorff_mm", e.hausdorff_mm},
          {"hausdorff_input_to_decoded_mm", e.to_decoded_max_mm},
          {"hausdorff_decoded_to_input_mm", e.to_reference_max_mm},
          {"outline_hausdorff_mm", e.outline_hausdorff_mm},
          {"surface_mean_mm", e.surface_mean_mm()}};
}

}  // namespace gvkit::tools
