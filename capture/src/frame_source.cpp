#include "gvkit/capture/frame_source.hpp"

#include <cmath>

#include "gvkit/capture/callback_frame_source.hpp"
#include "gvkit/capture/file_frame_source.hpp"
#include "gvkit/capture/libcamera_source.hpp"
#include "gvkit/capture/v4l2_source.hpp"

namespace gvkit {

Status FrameSourceOptions::check() const {
  auto bad = [](const std::string& field, const std::string& why) {
    return invalid_argument("frame source option " + field + ": " + why);
  };
  if (width < 0 || height < 0)
    return bad("size", std::to_string(width) + "x" + std::to_string(height) + " is negative");
  if ((width == 0) != (height == 0)) return bad("size", "give both width and height, or neither");
  if (!std::isfinite(fps) || fps < 0 || fps > 10000)
    return bad("fps", std::to_string(fps) + " is outside [0, 10000]");
  if (!std::isfinite(exposure_us) || exposure_us < 0 || exposure_us > 60e6)
    return bad("exposure_us", std::to_string(exposure_us) + " is outside [0, 60 s]");
  if (pixel_format != "auto" && pixel_format != "GREY" && pixel_format != "Y16" &&
      pixel_format != "YUYV" && pixel_format != "MJPG")
    return bad("pixel_format", "'" + pixel_format + "' is not one of auto, GREY, Y16, YUYV, MJPG");
  if (buffer_count < 2 || buffer_count > 32)
    return bad("buffer_count", std::to_string(buffer_count) + " is outside [2, 32]");
  if (timeout_ms < 1 || timeout_ms > 600000)
    return bad("timeout_ms", std::to_string(timeout_ms) + " is outside [1, 600000]");
  if (frame_count < 0) return bad("frame_count", std::to_string(frame_count) + " is negative");
  if (paced && fps <= 0) return bad("paced", "needs fps > 0");
  if (pattern_cycle < 0 || pattern_cycle > 1024)
    return bad("pattern_cycle", std::to_string(pattern_cycle) + " is outside [0, 1024]");
  if (cue_frames < 0 || (cue_frames > 0 && cue_frames >= pattern_cycle))
    return bad("cue_frames", std::to_string(cue_frames) + " must be in [0, pattern_cycle)");
  if (drop_late && !paced) return bad("drop_late", "needs paced");
  return Status::ok();
}

Result<std::unique_ptr<FrameSource>> FrameSource::create(const std::string& uri,
                                                         const FrameSourceOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const size_t colon = uri.find(':');
  if (colon == std::string::npos)
    return invalid_argument("source '" + uri +
                            "': expected v4l2:/dev/videoN, libcamera:<id>, file:<path> or "
                            "synthetic:");
  const std::string scheme = uri.substr(0, colon);
  const std::string rest = uri.substr(colon + 1);
  if (scheme == "file") {
    if (rest.empty()) return invalid_argument("source '" + uri + "': no path after file:");
    return open_file_source(rest, options);
  }
  if (scheme == "v4l2") {
    if (rest.empty()) return invalid_argument("source '" + uri + "': no device after v4l2:");
    return open_v4l2_source(rest, options);
  }
  if (scheme == "libcamera") return open_libcamera_source(rest, options);
  if (scheme == "synthetic") {
    if (!options.synthetic_generator)
      return unsupported("source '" + uri +
                         "': no synthetic generator was given (FrameSourceOptions::"
                         "synthetic_generator: the projector-camera renderer)");
    return make_callback_source(options.synthetic_generator, options, uri);
  }
  return invalid_argument("source '" + uri + "': unknown scheme '" + scheme +
                          "' (expected v4l2, libcamera, file or synthetic)");
}

}  // namespace gvkit
