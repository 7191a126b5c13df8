// gvkit: one command-line program, one subcommand per file in tools/.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "command.hpp"
#include "gvkit/core/allocator_tuning.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/version.hpp"

int main(int argc, char** argv) {
  // Frame after frame the stages allocate the same large arrays: keep freed memory for reuse.
  gvkit::tune_allocator_for_frames();
  CLI::App app{"gvkit: structured-light face capture to compact, playable geometry videos"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("gvkit ") + gvkit::version_string());
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Print debug messages");
  app.add_flag("-q,--quiet", quiet, "Print only errors");
  app.parse_complete_callback([&] {
    gvkit::set_log_level(verbose ? gvkit::LogLevel::kDebug
                         : quiet ? gvkit::LogLevel::kError
                                 : gvkit::LogLevel::kInfo);
  });

  gvkit::tools::add_info_command(app);
  gvkit::tools::add_synth_command(app);
  gvkit::tools::add_reconstruct_command(app);
  gvkit::tools::add_devices_command(app);
  gvkit::tools::add_calibrate_command(app);
  gvkit::tools::add_record_command(app);
  gvkit::tools::add_capture_command(app);
  gvkit::tools::add_facemap_command(app);
  gvkit::tools::add_facemap_map_command(app);
  gvkit::tools::add_facemap_compare_command(app);
  gvkit::tools::add_facemap_make_domain_command(app);
  gvkit::tools::add_facemap_ict_sequence_command(app);
  gvkit::tools::add_facemap_landmarks_command(app);
  gvkit::tools::add_encode_command(app);
  gvkit::tools::add_decode_command(app);
  gvkit::tools::add_export_command(app);
  gvkit::tools::add_run_command(app);
  gvkit::tools::add_summary_command(app);
#ifdef GVKIT_WITH_PLAYER
  gvkit::tools::add_play_command(app);
  gvkit::tools::add_render_command(app);
  gvkit::tools::add_compare_command(app);
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const gvkit::tools::CommandFailed& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: internal: %s\n", e.what());
    return 2;
  }
  return 0;
}
