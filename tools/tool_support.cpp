#include "tool_support.hpp"

#include <algorithm>
#include <cstdio>
#include <thread>

#include "gvkit/core/json_io.hpp"

namespace gvkit::tools {
namespace fs = std::filesystem;

Result<std::pair<int, int>> parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
      w <= 0 || h <= 0)
    return invalid_argument("size '" + text + "' is not WxH (e.g. 640x480)");
  return std::make_pair(w, h);
}

Result<ExrCompression> exr_compression_option(const std::string& text) {
  Result<ExrCompression> compression = parse_exr_compression(text);
  if (!compression.is_ok())
    return invalid_argument("--exr-compression: " + compression.status().message());
  return compression;
}

const char* const kExrCompressionHelp =
    "Compression of the written EXRs, all lossless: zip (the smallest files), rle or none "
    "(faster to write: a 320x320 geometry image in about 3-8 ms instead of 25-30, in a file "
    "1.2-1.4x larger; all read in 7-10 ms)";

int command_threads(int requested, int at_most) {
  if (requested > 0) return requested;
  return static_cast<int>(
      std::clamp(std::thread::hardware_concurrency(), 1u, static_cast<unsigned>(at_most)));
}

Status failures_status(const std::vector<std::string>& failures, size_t total) {
  if (failures.empty()) return Status::ok();
  std::string message = std::to_string(failures.size()) + " of " + std::to_string(total) +
                        " frames failed (the others were written): ";
  for (size_t i = 0; i < failures.size() && i < 5; ++i) message += (i ? "; " : "") + failures[i];
  if (failures.size() > 5) message += "; ...";
  return corrupt_data(message);
}

FrameStatsFile::FrameStatsFile(fs::path dir, nlohmann::json header, bool resume)
    : path_(std::move(dir) / "stats.json"), header_(std::move(header)) {
  if (!resume) return;
  std::error_code ec;
  if (!fs::exists(path_, ec)) return;
  Result<nlohmann::json> old = read_json(path_);
  if (!old.is_ok() || !old->is_object() || !old->contains("frames") ||
      !(*old)["frames"].is_array()) {
    resume_note_ = path_.string() + " is unreadable; every frame is computed again";
    return;
  }
  if (old->value("options", nlohmann::json()) != header_.value("options", nlohmann::json())) {
    resume_note_ =
        path_.string() + " was written with other options; every frame is computed again";
    return;
  }
  for (const auto& f : (*old)["frames"])
    if (f.is_object() && f.contains("index") && f["index"].is_number_integer())
      previous_[f["index"].get<int64_t>()] = f;
}

std::optional<nlohmann::json> FrameStatsFile::previous(int64_t index) const {
  const auto it = previous_.find(index);
  if (it == previous_.end()) return std::nullopt;
  return it->second;
}

Status FrameStatsFile::write_locked(const nlohmann::json* summary,
                                    const nlohmann::json& frames) const {
  nlohmann::json out = header_;
  out["complete"] = summary != nullptr;
  if (summary) out["summary"] = *summary;
  out["frames"] = frames;
  return write_json(path_, out);
}

Status FrameStatsFile::record(int64_t index, nlohmann::json entry) {
  std::lock_guard<std::mutex> lock(mutex_);
  recorded_[index] = std::move(entry);
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& [i, f] : recorded_) frames.push_back(f);
  return write_locked(nullptr, frames);
}

std::vector<nlohmann::json> FrameStatsFile::entries() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<nlohmann::json> out;
  for (const auto& [i, f] : recorded_) out.push_back(f);
  return out;
}

Status FrameStatsFile::finish(const nlohmann::json& summary, const nlohmann::json& frames) {
  std::lock_guard<std::mutex> lock(mutex_);
  return write_locked(&summary, frames);
}

Status FrameStatsFile::finish(const nlohmann::json& summary) {
  nlohmann::json frames = nlohmann::json::array();
  for (auto& f : entries()) frames.push_back(std::move(f));
  return finish(summary, frames);
}

bool all_exist(const std::vector<fs::path>& paths) {
  std::error_code ec;
  for (const auto& p : paths)
    if (!fs::is_regular_file(p, ec)) return false;
  return true;
}

}  // namespace gvkit::tools
