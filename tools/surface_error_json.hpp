#pragma once
// The surface figures of codec/surface_metrics.hpp as the flat JSON keys every stats.json uses:
// normal_mean_deg, normal_p95_deg, normal_max_deg (normal-angle error, degrees), hausdorff_mm,
// its two directed parts hausdorff_input_to_decoded_mm and hausdorff_decoded_to_input_mm,
// outline_hausdorff_mm and surface_mean_mm (vertex-to-surface distances, mm).

#include <nlohmann/json.hpp>

#include "gvkit/codec/surface_metrics.hpp"

namespace gvkit::tools {

nlohmann::json surface_error_json(const codec::SurfaceError& e);

}  // namespace gvkit::tools
