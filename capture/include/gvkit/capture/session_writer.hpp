#pragma once
// Writes a session folder (session_info.hpp) append-only: each frame's images are written
// (atomically) before session.json is rewritten (atomically) to list it, so a crash loses at
// most the frame in flight and the folder still opens. append() is thread-safe; frames may
// arrive out of order and are listed sorted by index.

#include <filesystem>
#include <memory>
#include <mutex>

#include "gvkit/capture/session_info.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

class SessionWriter {
 public:
  // Creates the folder (which must not hold a session.json already), writes the calibration and
  // an empty session.json. info.frames is ignored.
  static Result<std::unique_ptr<SessionWriter>> create(const std::filesystem::path& dir,
                                                       const SessionInfo& info,
                                                       const Calibration& calibration);

  // Writes frame_NNNNNN_kK.png for every image and lists the frame. Fails naming the frame on
  // a wrong image count, size or depth, or an I/O error.
  Status append(const FringeSet& fringes);
  // Counts frames the source dropped (listed in session.json).
  Status add_dropped(int64_t count);

  const std::filesystem::path& dir() const { return dir_; }
  SessionInfo info() const;

 private:
  SessionWriter() = default;
  Status write_info_locked() const;

  std::filesystem::path dir_;
  SessionInfo info_;
  mutable std::mutex mutex_;
};

}  // namespace gvkit::capture
