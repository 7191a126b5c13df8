#pragma once
// The result table of a work folder written by `gvkit run` (or by the stage commands with the
// same layout): per stage the frames in and out, the stage's key figures and its time, read from
// each stage's stats.json.
//
//   WORK/session/session.json        synth (or the user's session, when copied there)
//   WORK/scans/stats.json            reconstruct: RMS depth error against ground truth (mm)
//   WORK/faces/stats.json            facemap clean: frames cleaned, failures
//   WORK/gv/stats.json               facemap map: flips, feature drift, temporal coherence
//   WORK/face.gvid.stats.json        encode: bits per vertex per frame, geometry PSNR, normal
//                                    error and Hausdorff distance
//   WORK/decoded/stats.json          decode: frames decoded
//   WORK/face.stats.json             render (face.mp4)
//   WORK/compare.stats.json          compare (compare.png, compare.mp4): normal error, Hausdorff
//   WORK/run.json                    time per stage ({"stages": [{"name", "seconds", ...}]})

#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit::tools {

struct StageSummary {
  std::string stage;
  int64_t frames_in = -1, frames_out = -1;  // -1: not known
  double seconds = -1;                      // -1: not recorded
  bool kept = false;                        // outputs (and time) from an earlier run
  std::string figures;                      // the stage's key figures, one line
  std::vector<std::string> failures;        // "frame N: why", for stages that lost frames
};

// The stages found in work, in pipeline order; stages without their stats file are left out.
// Fails naming the file when a stats file exists but is not valid JSON of the expected shape.
Result<std::vector<StageSummary>> summarize_work_folder(const std::filesystem::path& work);

// The table as text: one row per stage ("clean  11/30  16.2 s  ..."), a total time, and the
// failed frames of each stage that lost some (at most max_failures listed per stage).
std::string format_summary_table(const std::vector<StageSummary>& stages, int max_failures = 5);

}  // namespace gvkit::tools
