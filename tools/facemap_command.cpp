// gvkit facemap: the expression-invariant face parameterization, one subcommand per stage
// (clean: scans or meshes -> 4-boundary face meshes).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace gvkit::tools {

void add_facemap_command(CLI::App& app) {
  CLI::App* facemap =
      app.add_subcommand("facemap", "Map faces onto the canonical domain (clean, ...)");
  facemap->require_subcommand(1);
  add_facemap_clean_command(*facemap);
}

}  // namespace gvkit::tools
