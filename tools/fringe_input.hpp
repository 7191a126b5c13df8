#pragma once
// The input of `gvkit reconstruct` (and `gvkit run`) when it is a plain folder of fringe images
// rather than a session: which pattern set, which calibration, how the calibration is fitted to
// the images. Every failure names the folder, the image file and the calibration file involved,
// and says which option to give.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/stereo_reconstructor.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/calibration_io.hpp"

namespace gvkit::tools {

struct FringeInputArgs {
  std::string pattern;                   // --pattern NAME or SPEC.json
  std::vector<std::string> calibration;  // --calibration FILE [FILE ...]
  std::string projector_size;            // --projector-size WxH ("" = from the file)
  std::string calibration_unit = "mm";   // --calibration-unit mm|cm|m
  bool rescale_calibration = false;      // --rescale-calibration
  capture::FringeFolderOptions folder;   // --images, --exclude, --sliding
};

struct FringeFolderInput {
  std::unique_ptr<capture::PatternSet> patterns;
  capture::FringeFolder folder;
  Calibration calibration;
  std::string calibration_note;  // how sizes and scale were settled, for the log and stats.json
};

// A camera pair: the same patterns seen by two cameras, in DIR/left + DIR/right (or DIR/cam0 +
// DIR/cam1), one image per pattern each, equally many.
struct StereoFolderInput {
  std::unique_ptr<capture::PatternSet> patterns;
  capture::FringeFolder left, right;
  capture::StereoCalibration calibration;
  std::string layout;  // "left/right" or "cam0/cam1"
};

// The pair of subfolders of dir when it holds a camera pair's images, else empty.
std::vector<std::filesystem::path> stereo_subfolders(const std::filesystem::path& dir);

// Resolves a camera pair: pattern set (absolute ones only), both folders (equal counts, equal
// image sizes), the stereo calibration (OpenCV stereo_calib layout, or any two-device layout)
// read for the images' size. Fails naming the folders or files.
Result<StereoFolderInput> open_stereo_folder(const std::filesystem::path& dir,
                                             const FringeInputArgs& args,
                                             const capture::PatternSetOptions& pattern_options);

// The calibration read options of the arguments (projector size, unit). Fails naming the option.
Result<CalibrationReadOptions> calibration_read_options(const FringeInputArgs& args);

// Resolves a plain folder: pattern set (or the message listing the pattern sets that fit the
// image count and the options to give), folder listing, calibration read with the images' size
// and fitted to it (or the message naming the image and calibration files when the resolutions
// differ, suggesting --rescale-calibration where the aspect ratios match).
Result<FringeFolderInput> open_fringe_folder(const std::filesystem::path& dir,
                                             const FringeInputArgs& args,
                                             const capture::PatternSetOptions& pattern_options);

// Fits a calibration read for `calibration_names` to images of `image_size` (the first being
// `image`): unchanged when the sizes agree; rescaled when asked and the aspect ratios match;
// otherwise the failure naming both files. A calibration whose camera size came from the images
// is checked for a principal point inside them.
Result<Calibration> fit_calibration_to_images(const LoadedCalibration& loaded, cv::Size image_size,
                                              const std::filesystem::path& image,
                                              const std::string& calibration_names, bool rescale,
                                              std::string* note = nullptr);

}  // namespace gvkit::tools
