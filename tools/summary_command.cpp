// gvkit summary WORK: the result table of a work folder written by `gvkit run` or
// scripts/main-job (frames in/out, key figures and time per stage; see work_summary.hpp).
#include <cstdio>
#include <memory>
#include <string>

#include "command.hpp"
#include "work_summary.hpp"

namespace gvkit::tools {

void add_summary_command(CLI::App& app) {
  auto work = std::make_shared<std::string>();
  auto max_failures = std::make_shared<int>(5);
  auto* cmd = app.add_subcommand(
      "summary", "Print the result table of a work folder (gvkit run, scripts/main-job)");
  cmd->add_option("work", *work, "Work folder")->required();
  cmd->add_option("--failures", *max_failures, "Failed frames listed per stage")
      ->capture_default_str();
  cmd->callback([work, max_failures] {
    if (*max_failures < 0) throw CommandFailed(invalid_argument("--failures must be >= 0"));
    const auto stages = value_or_throw(summarize_work_folder(*work));
    if (stages.empty())
      throw CommandFailed(not_found(*work + ": no stage outputs (stats.json) found"));
    std::printf("%s", format_summary_table(stages, *max_failures).c_str());
  });
}

}  // namespace gvkit::tools
