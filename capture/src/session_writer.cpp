#include "gvkit/capture/session_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <future>
#include <vector>

#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::capture {
namespace fs = std::filesystem;

Result<std::unique_ptr<SessionWriter>> SessionWriter::create(const fs::path& dir,
                                                             const SessionInfo& info,
                                                             const Calibration& calibration) {
  std::error_code ec;
  if (fs::exists(dir / "session.json", ec))
    return invalid_argument(dir.string() + ": already holds a session (session.json)");
  if (info.width <= 0 || info.height <= 0 || info.images_per_frame <= 0)
    return invalid_argument(dir.string() + ": session needs an image size and images per frame");
  GVKIT_RETURN_IF_ERROR(ensure_directory(dir / "frames"));
  GVKIT_RETURN_IF_ERROR(write_calibration(dir / info.calibration_file, calibration));
  std::unique_ptr<SessionWriter> w(new SessionWriter());
  w->dir_ = dir;
  w->info_ = info;
  w->info_.frames.clear();
  if (!info.ground_truth_dir.empty())
    GVKIT_RETURN_IF_ERROR(ensure_directory(dir / info.ground_truth_dir));
  GVKIT_RETURN_IF_ERROR(w->write_info_locked());
  return w;
}

Status SessionWriter::write_info_locked() const {
  return write_json(dir_ / "session.json", info_.to_json());
}

Status SessionWriter::append(const FringeSet& fringes) {
  const std::string frame = "frame " + std::to_string(fringes.index);
  if (static_cast<int>(fringes.images.size()) != info_.images_per_frame)
    return invalid_argument(frame + ": " + std::to_string(fringes.images.size()) +
                            " images, the session has " + std::to_string(info_.images_per_frame));
  Status s = fringes.check();
  if (!s) return s.with_context(frame);
  if (fringes.size() != cv::Size(info_.width, info_.height))
    return invalid_argument(frame + ": image size differs from the session's");
  const int depth = info_.bit_depth > 8 ? CV_16U : CV_8U;
  SessionFrame entry;
  entry.index = fringes.index;
  entry.timestamp = fringes.timestamp;
  for (size_t k = 0; k < fringes.images.size(); ++k) {
    if (fringes.images[k].depth() != depth)
      return invalid_argument(frame + ": image " + std::to_string(k) + " is not " +
                              (depth == CV_16U ? "16" : "8") + "-bit as the session");
    char name[64];
    std::snprintf(name, sizeof(name), "frames/frame_%06lld_k%zu.png",
                  static_cast<long long>(fringes.index), k);
    entry.images.push_back(name);
  }
  // The images are encoded and written (each with its fsyncs) concurrently: PNG encoding uses
  // both cores and the fsyncs overlap, so a set costs about one image's wall time, not three.
  // session.json lists the set only after every image is on disk.
  std::vector<std::future<Status>> written;
  for (size_t k = 1; k < entry.images.size(); ++k)
    written.push_back(std::async(std::launch::async, [this, &entry, &fringes, k] {
      return write_image(dir_ / entry.images[k], fringes.images[k]);
    }));
  Status first = write_image(dir_ / entry.images[0], fringes.images[0]);
  for (std::future<Status>& w : written) {
    Status s_k = w.get();
    if (first.is_ok() && !s_k.is_ok()) first = s_k;
  }
  GVKIT_RETURN_IF_ERROR(first);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& frames = info_.frames;
  auto at = std::lower_bound(frames.begin(), frames.end(), entry.index,
                             [](const SessionFrame& f, int64_t i) { return f.index < i; });
  if (at != frames.end() && at->index == entry.index)
    *at = entry;
  else
    frames.insert(at, entry);
  return write_info_locked();
}

Status SessionWriter::add_dropped(int64_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  info_.dropped_frames += count;
  return write_info_locked();
}

SessionInfo SessionWriter::info() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return info_;
}

}  // namespace gvkit::capture
