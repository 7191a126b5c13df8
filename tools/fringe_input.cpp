#include "fringe_input.hpp"

#include <cmath>
#include <cstdio>

#include "gvkit/core/image_io.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace fs = std::filesystem;
namespace {

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

std::string joined(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// What to say when a plain folder comes without --pattern or --calibration.
Status missing_inputs(const fs::path& dir, const FringeInputArgs& args) {
  auto images = capture::list_fringe_images(dir, args.folder);
  if (!images)
    return Status(images.status().code(),
                  images.status().message() +
                      "; nor is it a session (no session.json): give a session folder, or a "
                      "folder of fringe images with --pattern and --calibration");
  const int n = static_cast<int>(images->size());
  std::string message = dir.string() + ": a folder of " + std::to_string(n) +
                        " fringe images (no session.json) needs ";
  if (args.pattern.empty() && args.calibration.empty())
    message += "--pattern and --calibration";
  else
    message += args.pattern.empty() ? "--pattern" : "--calibration";
  if (args.pattern.empty()) {
    message +=
        ". The pattern set cannot be inferred from the images; give --pattern NAME, or "
        "--pattern SPEC.json for an order, shift sign, pitch or references no name "
        "describes (docs/real-data.md)";
    const auto one_frame = capture::pattern_set_candidates(n);
    if (!one_frame.empty())
      message += ". Pattern sets of " + std::to_string(n) +
                 " images (the folder as one frame): " + joined(one_frame, ", ");
    std::string divisors;
    for (int k = 3; k <= n / 2; ++k)
      if (n % k == 0 && !capture::pattern_set_candidates(k).empty())
        divisors +=
            "; k = " + std::to_string(k) + ": " + joined(capture::pattern_set_candidates(k), ", ");
    if (!divisors.empty())
      message +=
          ". Per frame of k images (the folder as " + std::to_string(n) + "/k frames)" + divisors;
    message +=
        ". <P> is the number of fringe periods across the projector width; --sliding "
        "reads a continuous sequence as overlapping windows";
  }
  if (args.calibration.empty())
    message +=
        ". --calibration FILE [FILE ...] takes gvkit, SLStudio, procam/scan3d-capture, "
        "OpenCV stereo_calib or OpenCV camera-sample files (add --projector-size WxH "
        "when the file does not record the projector's size)";
  return invalid_argument(message);
}

}  // namespace

Result<CalibrationReadOptions> calibration_read_options(const FringeInputArgs& args) {
  CalibrationReadOptions o;
  if (!args.projector_size.empty()) {
    auto size = parse_size(args.projector_size);
    if (!size) return size.status().with_context("--projector-size");
    o.projector_size = {size->first, size->second};
  }
  if (args.calibration_unit == "mm")
    o.length_unit_mm = 1;
  else if (args.calibration_unit == "cm")
    o.length_unit_mm = 10;
  else if (args.calibration_unit == "m")
    o.length_unit_mm = 1000;
  else
    return invalid_argument("--calibration-unit must be mm, cm or m, is '" + args.calibration_unit +
                            "'");
  return o;
}

Result<Calibration> fit_calibration_to_images(const LoadedCalibration& loaded, cv::Size image_size,
                                              const fs::path& image,
                                              const std::string& calibration_names, bool rescale,
                                              std::string* note) {
  const Calibration& c = loaded.calibration;
  const cv::Size calibrated(c.camera_width, c.camera_height);
  if (!loaded.camera_size_from_file) {
    // The size came from the images: only the principal point can betray another resolution.
    const double cx = c.camera_K(0, 2), cy = c.camera_K(1, 2);
    if (cx < 0 || cy < 0 || cx > image_size.width || cy > image_size.height) {
      char text[64];
      std::snprintf(text, sizeof text, "(%.1f, %.1f)", cx, cy);
      return failed_precondition(
          calibration_names + ": the camera's principal point " + text + " lies outside the " +
          size_text(image_size) + " images (" + image.string() +
          "): a calibration of another resolution? It records no image size, so it cannot be "
          "rescaled; recalibrate at this resolution");
    }
    if (note) *note = "camera size " + size_text(image_size) + " taken from the images";
    return c;
  }
  if (calibrated == image_size) return c;
  const double scale = static_cast<double>(image_size.width) / calibrated.width;
  const bool same_aspect = std::abs(scale * calibrated.height / image_size.height - 1) <= 0.005;
  char factor[32];
  std::snprintf(factor, sizeof factor, "%.4g", scale);
  if (rescale && same_aspect) {
    GVKIT_ASSIGN_OR_RETURN(Calibration scaled, rescale_camera(c, image_size));
    if (note)
      *note = "camera intrinsics rescaled by " + std::string(factor) + " from " +
              size_text(calibrated) + " to " + size_text(image_size);
    return scaled;
  }
  std::string message = image.string() + " is " + size_text(image_size) + ", but " +
                        calibration_names + " calibrates a " + size_text(calibrated) +
                        " camera: a calibration of another resolution";
  if (same_aspect)
    message +=
        "; the aspect ratio matches, so --rescale-calibration would scale its camera "
        "intrinsics by " +
        std::string(factor) + " (binned or resized images)";
  else
    message += rescale ? "; --rescale-calibration cannot help: the aspect ratios differ "
                         "(cropped images?); recalibrate at this resolution"
                       : "; the aspect ratios differ (cropped images?): recalibrate at this "
                         "resolution";
  return failed_precondition(message);
}

Result<FringeFolderInput> open_fringe_folder(const fs::path& dir, const FringeInputArgs& args,
                                             const capture::PatternSetOptions& pattern_options) {
  if (args.pattern.empty() || args.calibration.empty()) return missing_inputs(dir, args);
  FringeFolderInput in;
  GVKIT_ASSIGN_OR_RETURN(in.patterns, capture::create_pattern_set(args.pattern, pattern_options));
  GVKIT_ASSIGN_OR_RETURN(in.folder,
                         capture::list_fringe_folder(dir, in.patterns->image_count(), args.folder));
  const fs::path first = in.folder.frames.front().front();
  GVKIT_ASSIGN_OR_RETURN(cv::Mat image, read_image(first, true));
  GVKIT_ASSIGN_OR_RETURN(CalibrationReadOptions read_options, calibration_read_options(args));
  read_options.camera_size = image.size();
  std::vector<fs::path> paths(args.calibration.begin(), args.calibration.end());
  GVKIT_ASSIGN_OR_RETURN(LoadedCalibration loaded, read_calibration(paths, read_options));
  std::string names;
  for (const fs::path& p : paths) names += (names.empty() ? "" : " + ") + p.string();
  GVKIT_ASSIGN_OR_RETURN(in.calibration,
                         fit_calibration_to_images(loaded, image.size(), first, names,
                                                   args.rescale_calibration, &in.calibration_note));
  std::string layout = std::string(calibration_format_name(loaded.format)) + " layout";
  if (!loaded.projector_size_from_file)
    layout += ", projector " +
              size_text({in.calibration.projector_width, in.calibration.projector_height}) +
              " from --projector-size";
  in.calibration_note = in.calibration_note.empty() ? layout : layout + ", " + in.calibration_note;
  return in;
}

std::vector<fs::path> stereo_subfolders(const fs::path& dir) {
  std::error_code ec;
  for (auto [a, b] : {std::pair{"left", "right"}, std::pair{"cam0", "cam1"}})
    if (fs::is_directory(dir / a, ec) && fs::is_directory(dir / b, ec)) return {dir / a, dir / b};
  return {};
}

Result<StereoFolderInput> open_stereo_folder(const fs::path& dir, const FringeInputArgs& args,
                                             const capture::PatternSetOptions& pattern_options) {
  const std::vector<fs::path> sides = stereo_subfolders(dir);
  GVKIT_CHECK(sides.size() == 2);
  if (args.pattern.empty() || args.calibration.empty()) {
    Status s = missing_inputs(sides[0], args);
    return Status(s.code(), dir.string() + " (a camera pair): " + s.message());
  }
  StereoFolderInput in;
  in.layout = sides[0].filename().string() + "/" + sides[1].filename().string();
  GVKIT_ASSIGN_OR_RETURN(in.patterns, capture::create_pattern_set(args.pattern, pattern_options));
  GVKIT_ASSIGN_OR_RETURN(
      in.left, capture::list_fringe_folder(sides[0], in.patterns->image_count(), args.folder));
  GVKIT_ASSIGN_OR_RETURN(
      in.right, capture::list_fringe_folder(sides[1], in.patterns->image_count(), args.folder));
  if (in.left.images.size() != in.right.images.size())
    return invalid_argument(sides[0].string() + " holds " + std::to_string(in.left.images.size()) +
                            " images, " + sides[1].string() + " " +
                            std::to_string(in.right.images.size()) +
                            ": a camera pair needs one image per pattern in each");
  GVKIT_ASSIGN_OR_RETURN(cv::Mat first_left, read_image(in.left.images.front(), true));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat first_right, read_image(in.right.images.front(), true));
  if (first_left.size() != first_right.size())
    return invalid_argument(
        in.right.images.front().string() + " is " + size_text(first_right.size()) + ", but " +
        in.left.images.front().string() + " is " + size_text(first_left.size()) +
        ": the two cameras must give images of one size");
  GVKIT_ASSIGN_OR_RETURN(CalibrationReadOptions read_options, calibration_read_options(args));
  read_options.camera_size = first_left.size();
  std::vector<fs::path> paths(args.calibration.begin(), args.calibration.end());
  std::string names;
  for (const fs::path& p : paths) names += (names.empty() ? "" : " + ") + p.string();
  GVKIT_ASSIGN_OR_RETURN(TwoDeviceCalibration devices,
                         read_two_device_calibration(paths, read_options));
  Result<capture::StereoCalibration> calibration =
      capture::stereo_calibration(devices, first_left.size());
  if (!calibration)
    return calibration.status().with_context(names + " with " + in.left.images.front().string());
  in.calibration = *calibration;
  return in;
}

}  // namespace gvkit::tools
