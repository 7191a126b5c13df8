#include "gvkit/capture/session_info.hpp"

#include <cmath>

namespace gvkit::capture {

nlohmann::json SessionInfo::to_json() const {
  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["calibration"] = calibration_file;
  j["pattern"] = {{"name", pattern}, {"images_per_frame", images_per_frame}};
  j["fps"] = fps;
  j["image_size"] = {width, height};
  j["bit_depth"] = bit_depth;
  j["dropped_frames"] = dropped_frames;
  if (!ground_truth_dir.empty()) j["ground_truth"] = ground_truth_dir;
  if (depth_prior_mm > 0) j["depth_prior_mm"] = depth_prior_mm;
  j["source"] = source;
  nlohmann::json frames_json = nlohmann::json::array();
  for (const SessionFrame& f : frames)
    frames_json.push_back(
        {{"index", f.index}, {"timestamp_ns", f.timestamp.count()}, {"images", f.images}});
  j["frames"] = frames_json;
  return j;
}

Result<SessionInfo> SessionInfo::from_json(const nlohmann::json& j, const std::string& where) {
  SessionInfo s;
  try {
    if (!j.is_object() || j.value("format", std::string()) != kFormat)
      return corrupt_data(where + ": not a gvkit session (format must be \"" + kFormat + "\")");
    const int version = j.at("version").get<int>();
    if (version != kVersion)
      return unsupported(where + ": session version " + std::to_string(version) +
                         " is not supported (this build reads " + std::to_string(kVersion) + ")");
    s.calibration_file = j.at("calibration").get<std::string>();
    s.pattern = j.at("pattern").at("name").get<std::string>();
    s.images_per_frame = j.at("pattern").at("images_per_frame").get<int>();
    s.fps = j.at("fps").get<double>();
    s.width = j.at("image_size").at(0).get<int>();
    s.height = j.at("image_size").at(1).get<int>();
    s.bit_depth = j.at("bit_depth").get<int>();
    s.dropped_frames = j.value("dropped_frames", int64_t{0});
    s.ground_truth_dir = j.value("ground_truth", std::string());
    s.depth_prior_mm = j.value("depth_prior_mm", 0.0);
    if (j.contains("source")) s.source = j["source"];
    for (const auto& f : j.at("frames")) {
      SessionFrame frame;
      frame.index = f.at("index").get<int64_t>();
      frame.timestamp = Timestamp(f.at("timestamp_ns").get<int64_t>());
      frame.images = f.at("images").get<std::vector<std::string>>();
      if (static_cast<int>(frame.images.size()) != s.images_per_frame)
        return corrupt_data(where + ": frame " + std::to_string(frame.index) + " lists " +
                            std::to_string(frame.images.size()) + " images, expected " +
                            std::to_string(s.images_per_frame));
      s.frames.push_back(std::move(frame));
    }
  } catch (const nlohmann::json::exception& e) {
    return corrupt_data(where + ": " + e.what());
  }
  if (s.width <= 0 || s.height <= 0 || s.images_per_frame <= 0)
    return corrupt_data(where + ": image size and images per frame must be positive");
  if (!(s.depth_prior_mm >= 0) || !std::isfinite(s.depth_prior_mm))
    return corrupt_data(where + ": depth_prior_mm must be a depth in mm (or absent)");
  return s;
}

}  // namespace gvkit::capture
