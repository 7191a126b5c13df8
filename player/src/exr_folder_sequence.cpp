#include "gvkit/player/exr_folder_sequence.hpp"

#include <chrono>
#include <cmath>
#include <system_error>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {
namespace fs = std::filesystem;
namespace {

// The "fps" field of stats.json or session.json in dir (top level or under "options"), if any.
double folder_fps(const fs::path& dir) {
  for (const char* name : {"stats.json", "session.json"}) {
    std::error_code ec;
    if (!fs::exists(dir / name, ec)) continue;
    auto json = read_json(dir / name);
    if (!json.is_ok() || !json->is_object()) continue;
    for (const auto* node : {&*json, json->contains("options") ? &(*json)["options"] : nullptr}) {
      if (node && node->is_object() && node->contains("fps") && (*node)["fps"].is_number()) {
        const double fps = (*node)["fps"].get<double>();
        if (std::isfinite(fps) && fps > 0) return fps;
      }
    }
  }
  return 30.0;
}

}  // namespace

Result<std::unique_ptr<ExrFolderSequence>> ExrFolderSequence::open(const fs::path& dir) {
  GVKIT_ASSIGN_OR_RETURN(std::vector<FrameFile> files, list_frame_files(dir, ".exr"));
  if (files.empty()) return not_found(dir.string() + ": no frame_NNNNNN.exr files in the folder");
  std::unique_ptr<ExrFolderSequence> seq(new ExrFolderSequence());
  seq->dir_ = dir;
  seq->files_ = std::move(files);
  for (const FrameFile& f : seq->files_) {
    std::error_code ec;
    const auto size = fs::file_size(f.path, ec);
    seq->file_bits_.push_back(ec ? -1 : static_cast<int64_t>(size) * 8);
  }
  seq->fps_ = folder_fps(dir);
  // The first frame that reads decides the kind; unreadable frames are reported when played.
  Status first_error;
  for (const FrameFile& f : seq->files_) {
    auto channels = read_exr(f.path);
    if (!channels.is_ok()) {
      if (first_error.is_ok()) first_error = channels.status();
      continue;
    }
    seq->kind_ = channels->count("Q") ? Kind::kRangeScan : Kind::kGeometryImage;
    return seq;
  }
  return first_error.with_context(dir.string() + ": no readable frame");
}

std::string ExrFolderSequence::name() const {
  std::string base = dir_.filename().string();
  if (base.empty()) base = dir_.parent_path().filename().string();
  return base + " (" + (kind_ == Kind::kRangeScan ? "range-scan" : "geometry-image") +
         " EXR folder, " + std::to_string(files_.size()) + " frames)";
}

Result<GeometryImage> ExrFolderSequence::frame(int64_t index) {
  GVKIT_CHECK(index >= 0 && index < frame_count(), "frame index out of range");
  const fs::path& path = files_[static_cast<size_t>(index)].path;
  GeometryImage image;
  if (kind_ == Kind::kRangeScan) {
    GVKIT_ASSIGN_OR_RETURN(RangeScan scan, read_range_scan_exr(path));
    GVKIT_ASSIGN_OR_RETURN(image, geometry_image_from_range_scan(scan));
  } else {
    GVKIT_ASSIGN_OR_RETURN(image, read_geometry_image_exr(path));
  }
  image.index = index;
  image.timestamp = std::chrono::duration_cast<Timestamp>(
      std::chrono::duration<double>(static_cast<double>(index) / fps_));
  return image;
}

std::optional<int64_t> ExrFolderSequence::frame_bits(int64_t index) const {
  GVKIT_CHECK(index >= 0 && index < frame_count(), "frame index out of range");
  const int64_t bits = file_bits_[static_cast<size_t>(index)];
  if (bits < 0) return std::nullopt;
  return bits;
}

}  // namespace gvkit::player
