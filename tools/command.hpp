#pragma once
// Shared plumbing of the gvkit subcommands: each tools/<name>_command.cpp registers one
// subcommand on the CLI11 app; failures travel as a Status and end the program with its message
// and a non-zero exit code.

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit::tools {

// Thrown by a subcommand's callback to end the run with "error: <message>" and exit code 1.
class CommandFailed : public std::runtime_error {
 public:
  explicit CommandFailed(const Status& status) : std::runtime_error(status.message()) {}
};

// Throws CommandFailed unless status is ok.
inline void throw_if_error(const Status& status) {
  if (!status.is_ok()) throw CommandFailed(status);
}
template <typename T>
T value_or_throw(Result<T> result) {
  if (!result.is_ok()) throw CommandFailed(result.status());
  return std::move(result).value();
}

void add_info_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_reconstruct_command(CLI::App& app);
void add_devices_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
void add_record_command(CLI::App& app);
void add_capture_command(CLI::App& app);
// `gvkit facemap` and its subcommands (tools/facemap_*_command.cpp).
void add_facemap_command(CLI::App& app);
void add_facemap_clean_command(CLI::App& facemap);

// The `gvkit facemap` subcommand group, created by whichever facemap subcommand registers first.
inline CLI::App* facemap_group(CLI::App& app) {
  try {
    return app.get_subcommand("facemap");
  } catch (const CLI::OptionNotFound&) {
    auto* group = app.add_subcommand("facemap", "Face meshes to geometry images on one domain");
    group->require_subcommand(1);
    return group;
  }
}
void add_facemap_map_command(CLI::App& app);
void add_facemap_compare_command(CLI::App& app);
void add_facemap_make_domain_command(CLI::App& app);
void add_facemap_ict_sequence_command(CLI::App& app);
void add_facemap_landmarks_command(CLI::App& app);
void add_encode_command(CLI::App& app);
void add_decode_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_summary_command(CLI::App& app);
#ifdef GVKIT_WITH_PLAYER
void add_play_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_compare_command(CLI::App& app);
#endif

}  // namespace gvkit::tools
