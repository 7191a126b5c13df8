#pragma once
// Small helpers shared by the subcommands: size parsing, thread counts, failure summaries, and the
// stats.json of the frame-by-frame commands (reconstruct, facemap clean, facemap map), which lets
// them resume.

#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::tools {

// "640x480" -> (640, 480). Fails naming the text.
Result<std::pair<int, int>> parse_size(const std::string& text);

// The value of a command's --exr-compression option ("zip", "rle" or "none"; exr_io.hpp).
// Fails naming the option and the text.
Result<ExrCompression> exr_compression_option(const std::string& text);

// The help text of --exr-compression.
extern const char* const kExrCompressionHelp;

// The threads a command runs: `requested` when > 0, else (0: automatic) the hardware threads,
// at least 1 and at most `at_most`.
int command_threads(int requested, int at_most);

// Ok when no frame failed; else "K of N frames failed: <first messages>" (corrupt data).
Status failures_status(const std::vector<std::string>& failures, size_t total);

// DIR/stats.json of a command that writes one output per frame. Each frame's entry is written as
// soon as the frame is done (the file then says "complete": false), so an interrupted run leaves
// the figures of every finished frame; finish() writes the summary and "complete": true. Frames
// are listed by index. Every write is atomic (temp file + rename).
//
// Resuming: with resume = true the entries of an earlier run in DIR are offered by previous()
// when that run used the same options (header["options"]); the command then keeps a frame whose
// outputs still exist instead of computing it again. Thread-safe.
class FrameStatsFile {
 public:
  // header: the fields besides "frames", "summary" and "complete" (command, input, options, ...).
  FrameStatsFile(std::filesystem::path dir, nlohmann::json header, bool resume);

  // The earlier run's entry for frame index; nullopt when not resuming or it has none.
  std::optional<nlohmann::json> previous(int64_t index) const;
  // Why earlier entries are not offered when resume was asked ("" when they are, or none exist).
  const std::string& resume_note() const { return resume_note_; }

  // Stores the entry of frame index (replacing an earlier one) and rewrites stats.json.
  Status record(int64_t index, nlohmann::json entry);
  // The entries recorded so far, by index.
  std::vector<nlohmann::json> entries() const;
  // Writes the final stats.json: header, summary, the given frame entries, "complete": true.
  Status finish(const nlohmann::json& summary, const nlohmann::json& frames);
  Status finish(const nlohmann::json& summary);  // with the recorded entries

  const std::filesystem::path& path() const { return path_; }

 private:
  Status write_locked(const nlohmann::json* summary, const nlohmann::json& frames) const;

  std::filesystem::path path_;
  nlohmann::json header_;
  std::map<int64_t, nlohmann::json> previous_, recorded_;
  std::string resume_note_;
  mutable std::mutex mutex_;
};

// True when every path exists (outputs of a frame written earlier; each written atomically, so
// an existing file is complete).
bool all_exist(const std::vector<std::filesystem::path>& paths);

}  // namespace gvkit::tools
