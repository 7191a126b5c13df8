#include "gvkit/capture/session_reader.hpp"

#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::capture {
namespace fs = std::filesystem;

Result<SessionReader> SessionReader::open(const fs::path& dir) {
  const fs::path json_path = dir / "session.json";
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json json, read_json(json_path));
  GVKIT_ASSIGN_OR_RETURN(SessionInfo info, SessionInfo::from_json(json, json_path.string()));
  GVKIT_ASSIGN_OR_RETURN(LoadedCalibration calibration,
                         read_calibration(dir / info.calibration_file));
  SessionReader r;
  r.dir_ = dir;
  r.info_ = std::move(info);
  r.calibration_ = calibration.calibration;
  return r;
}

Result<FringeSet> SessionReader::read_frame(size_t i) const {
  GVKIT_CHECK(i < info_.frames.size(), "frame position out of range");
  const SessionFrame& f = info_.frames[i];
  FringeSet set;
  set.index = f.index;
  set.timestamp = f.timestamp;
  for (const std::string& name : f.images) {
    GVKIT_ASSIGN_OR_RETURN(cv::Mat image, read_image(dir_ / name, true));
    set.images.push_back(image);
  }
  return set;
}

std::optional<fs::path> SessionReader::ground_truth_path(int64_t index) const {
  if (info_.ground_truth_dir.empty()) return std::nullopt;
  const fs::path p = frame_path(dir_ / info_.ground_truth_dir, index, ".exr");
  std::error_code ec;
  if (!fs::exists(p, ec)) return std::nullopt;
  return p;
}

}  // namespace gvkit::capture
