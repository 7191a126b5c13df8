#pragma once
// Calibration files. gvkit's own format is an OpenCV FileStorage (YAML, JSON or XML by extension)
// with the fields of Calibration. The layouts other structured-light and stereo tools write are
// recognised by their keys and converted (every one read through cv::FileStorage, so YAML, XML
// and JSON alike):
//
//   gvkit       camera_K camera_dist projector_K projector_dist R_cam_from_proj
//               t_cam_from_proj_mm camera_width camera_height projector_width projector_height
//   SLStudio    Kc kc Kp kp Rp Tp frameWidth frameHeight screenResX screenResY (Rp, Tp: X_proj =
//               Rp X_cam + Tp)
//   procam      cam_K cam_kc proj_K proj_kc R T (scan3d-capture and the tools derived from it;
//               cam_dist/proj_dist for the coefficients also accepted); R, T as
//               cv::stereoCalibrate(camera, projector) gives them: X_proj = R X_cam + T. No sizes.
//   stereo      M1 D1 M2 D2 R T [imageSize R1 R2 P1 P2 Q] (OpenCV's stereo_calib sample, often
//               split into intrinsics.yml + extrinsics.yml: give both files). Device 1 is the
//               camera (the left camera of a pair), device 2 the projector (the right camera);
//               X_2 = R X_1 + T.
//   camera      camera_matrix distortion_coefficients image_width image_height (OpenCV's
//               calibration sample; also cameraMatrix distCoeffs imageWidth imageHeight): one
//               file per device, the camera's first, the projector's second, plus a file with
//               R and T (X_proj = R X_cam + T).
//
// Keys are matched exactly, else ignoring case (Cam_K, Proj_Kc). Matrices may be opencv-matrix
// nodes or plain number lists. Lengths are taken as millimetres unless the options say otherwise.
// A file whose keys fit no layout fails with the keys it holds and the layouts expected.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

enum class CalibrationFormat { kGvkit, kSlStudio, kProcam, kStereo, kCameraFiles };

// "gvkit", "SLStudio", "procam", "stereo", "camera".
const char* calibration_format_name(CalibrationFormat format);

struct CalibrationReadOptions {
  // Device sizes for layouts that do not record them (0x0 = unknown). The camera size normally
  // comes from the images; the projector size from --projector-size. A file that records a
  // size wins; a given projector size that differs from the file's is an error.
  cv::Size camera_size, projector_size;
  double length_unit_mm = 1;  // millimetres per length unit of the file (10: cm, 1000: m)

  Status check() const;
};

struct LoadedCalibration {
  Calibration calibration;
  CalibrationFormat format = CalibrationFormat::kGvkit;
  bool camera_size_from_file = true;     // false: taken from options.camera_size
  bool projector_size_from_file = true;  // false: taken from options.projector_size
};

// The two devices of a stereo-style file, as written (device 2 seen from device 1).
struct TwoDeviceCalibration {
  cv::Matx33d K1 = cv::Matx33d::eye(), K2 = cv::Matx33d::eye();
  std::vector<double> dist1, dist2;
  cv::Size size1, size2;  // 0x0 when the file has none
  cv::Matx33d R_2_from_1 = cv::Matx33d::eye();
  cv::Vec3d t_2_from_1_mm{0, 0, 0};
  // Rectification, when the file holds it (OpenCV stereoRectify's outputs); else empty.
  cv::Mat R1, R2, P1, P2, Q;
  CalibrationFormat format = CalibrationFormat::kStereo;
};

// Reads any layout above from one file, or from several files whose keys together form one
// (intrinsics.yml + extrinsics.yml; camera.yml + projector.yml + extrinsics.yml), and checks the
// result (Calibration::check()). Fails naming the file(s) and the missing, malformed or
// non-finite field; a size the layout lacks and the options do not give is named with the
// option that supplies it.
Result<LoadedCalibration> read_calibration(const std::filesystem::path& path,
                                           const CalibrationReadOptions& options = {});
Result<LoadedCalibration> read_calibration(const std::vector<std::filesystem::path>& paths,
                                           const CalibrationReadOptions& options = {});
// The same files read as two devices without converting (for camera pairs). Sizes the files
// lack are taken from options.camera_size for both devices.
Result<TwoDeviceCalibration> read_two_device_calibration(
    const std::vector<std::filesystem::path>& paths, const CalibrationReadOptions& options = {});

// Writes gvkit's format (.yaml/.yml/.json/.xml), atomically.
Status write_calibration(const std::filesystem::path& path, const Calibration& calibration);
// Writes one of the foreign layouts above (for tests and for handing a calibration to other
// tools): kSlStudio, kProcam or kStereo in one file; kCameraFiles is not written.
Status write_calibration(const std::filesystem::path& path, const Calibration& calibration,
                         CalibrationFormat format);

}  // namespace gvkit
