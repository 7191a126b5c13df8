// gvkit facemap make-domain ICT_DIR -o FILE: derives the canonical domain spec from the ICT
// neutral face (how facemap/data/canonical_domain_v1.json was made).
#include <memory>
#include <string>

#include "command.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/facemap/canonical_domain.hpp"

namespace gvkit::tools {

void add_facemap_make_domain_command(CLI::App& app) {
  auto* cmd = facemap_group(app)->add_subcommand(
      "make-domain",
      "Derive the canonical domain (rectangle, eye and mouth holes) from ICT-FaceKit");
  auto ict_dir = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  cmd->add_option("ict_dir", *ict_dir, "ICT-FaceKit folder (generic_neutral_mesh.obj)")->required();
  cmd->add_option("-o,--output", *output, "Output JSON file")->required();
  cmd->callback([ict_dir, output] {
    const IctFaceModel model = value_or_throw(IctFaceModel::load(*ict_dir, {"jawOpen"}));
    const auto spec = value_or_throw(facemap::CanonicalDomainSpec::from_ict(model));
    throw_if_error(spec.write(*output));
    std::printf("%s: canonical domain v%d, %.1f x %.1f mm, holes of %zu/%zu/%zu points\n",
                output->c_str(), facemap::CanonicalDomainSpec::kVersion, spec.width_mm,
                spec.height_mm, spec.eye_right.size(), spec.eye_left.size(), spec.mouth.size());
  });
}

}  // namespace gvkit::tools
