#include "gvkit/core/calibration_io.hpp"

#include <cmath>

#include <opencv2/core/persistence.hpp>

#include "gvkit/core/atomic_file.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

Result<cv::Mat> read_matrix(const cv::FileStorage& fs, const std::string& key, int rows, int cols) {
  cv::FileNode node = fs[key];
  if (node.empty()) return corrupt_data("missing field " + key);
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    return corrupt_data("field " + key + " is not a matrix");
  }
  if (m.empty()) return corrupt_data("field " + key + " is not a matrix");
  if (rows > 0 && (m.rows * m.cols != rows * cols))
    return corrupt_data("field " + key + " must have " + std::to_string(rows) + "x" +
                        std::to_string(cols) + " entries, has " + std::to_string(m.rows) + "x" +
                        std::to_string(m.cols));
  m.convertTo(m, CV_64F);
  if (!cv::checkRange(m)) return corrupt_data("field " + key + " has non-finite entries");
  return m.reshape(1, rows > 0 ? rows : 1);
}

Result<int> read_int(const cv::FileStorage& fs, const std::string& key) {
  cv::FileNode node = fs[key];
  if (node.empty() || !(node.isInt() || node.isReal())) return corrupt_data("missing field " + key);
  return static_cast<int>(node.real());
}

std::vector<double> to_vector(const cv::Mat& m) {
  return std::vector<double>(m.begin<double>(), m.end<double>());
}

template <int M, int N>
cv::Matx<double, M, N> to_matx(const cv::Mat& m) {
  cv::Matx<double, M, N> out;
  for (int i = 0; i < M * N; ++i) out.val[i] = m.at<double>(i / N, i % N);
  return out;
}

// Drops trailing zero distortion coefficients beyond the first four: "0 0 0 0 0" means none.
std::vector<double> normalised_distortion(std::vector<double> d) {
  bool all_zero = true;
  for (double x : d) all_zero = all_zero && x == 0.0;
  if (all_zero) d.clear();
  return d;
}

Result<Calibration> read_slstudio(const cv::FileStorage& fs) {
  Calibration c;
  GVKIT_ASSIGN_OR_RETURN(cv::Mat Kc, read_matrix(fs, "Kc", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat kc, read_matrix(fs, "kc", 0, 0));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat Kp, read_matrix(fs, "Kp", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat kp, read_matrix(fs, "kp", 0, 0));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat Rp, read_matrix(fs, "Rp", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat Tp, read_matrix(fs, "Tp", 3, 1));
  GVKIT_ASSIGN_OR_RETURN(c.camera_width, read_int(fs, "frameWidth"));
  GVKIT_ASSIGN_OR_RETURN(c.camera_height, read_int(fs, "frameHeight"));
  GVKIT_ASSIGN_OR_RETURN(c.projector_width, read_int(fs, "screenResX"));
  GVKIT_ASSIGN_OR_RETURN(c.projector_height, read_int(fs, "screenResY"));
  c.camera_K = to_matx<3, 3>(Kc);
  c.projector_K = to_matx<3, 3>(Kp);
  c.camera_dist = normalised_distortion(to_vector(kc));
  c.projector_dist = normalised_distortion(to_vector(kp));
  // SLStudio stores proj_from_cam (X_proj = Rp X_cam + Tp); gvkit keeps cam_from_proj.
  const cv::Matx33d R_proj_from_cam = to_matx<3, 3>(Rp);
  const cv::Vec3d t_proj_from_cam(Tp.at<double>(0), Tp.at<double>(1), Tp.at<double>(2));
  c.R_cam_from_proj = R_proj_from_cam.t();
  c.t_cam_from_proj_mm = -(R_proj_from_cam.t() * t_proj_from_cam);
  if (!fs["cam_error"].empty()) c.camera_error_px = fs["cam_error"].real();
  if (!fs["proj_error"].empty()) c.projector_error_px = fs["proj_error"].real();
  if (!fs["stereo_error"].empty()) c.stereo_error_px = fs["stereo_error"].real();
  return c;
}

Result<Calibration> read_gvkit(const cv::FileStorage& fs) {
  Calibration c;
  GVKIT_ASSIGN_OR_RETURN(cv::Mat camera_K, read_matrix(fs, "camera_K", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat projector_K, read_matrix(fs, "projector_K", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat R, read_matrix(fs, "R_cam_from_proj", 3, 3));
  GVKIT_ASSIGN_OR_RETURN(cv::Mat t, read_matrix(fs, "t_cam_from_proj_mm", 3, 1));
  GVKIT_ASSIGN_OR_RETURN(c.camera_width, read_int(fs, "camera_width"));
  GVKIT_ASSIGN_OR_RETURN(c.camera_height, read_int(fs, "camera_height"));
  GVKIT_ASSIGN_OR_RETURN(c.projector_width, read_int(fs, "projector_width"));
  GVKIT_ASSIGN_OR_RETURN(c.projector_height, read_int(fs, "projector_height"));
  c.camera_K = to_matx<3, 3>(camera_K);
  c.projector_K = to_matx<3, 3>(projector_K);
  c.R_cam_from_proj = to_matx<3, 3>(R);
  c.t_cam_from_proj_mm = cv::Vec3d(t.at<double>(0), t.at<double>(1), t.at<double>(2));
  for (auto [key, target] :
       {std::pair{"camera_dist", &c.camera_dist}, std::pair{"projector_dist", &c.projector_dist}}) {
    if (fs[key].empty()) continue;
    GVKIT_ASSIGN_OR_RETURN(cv::Mat d, read_matrix(fs, key, 0, 0));
    *target = to_vector(d);
  }
  if (!fs["fringe_pitch_px"].empty()) c.fringe_pitch_px = fs["fringe_pitch_px"].real();
  if (!fs["camera_error_px"].empty()) c.camera_error_px = fs["camera_error_px"].real();
  if (!fs["projector_error_px"].empty()) c.projector_error_px = fs["projector_error_px"].real();
  if (!fs["stereo_error_px"].empty()) c.stereo_error_px = fs["stereo_error_px"].real();
  return c;
}

}  // namespace

Result<LoadedCalibration> read_calibration(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  cv::FileStorage storage;
  try {
    if (!storage.open(path.string(), cv::FileStorage::READ))
      return corrupt_data(path.string() + ": not an OpenCV YAML/JSON/XML file");
  } catch (const cv::Exception& e) {
    return corrupt_data(path.string() + ": cannot parse calibration: " + e.what());
  }
  LoadedCalibration loaded;
  Result<Calibration> calibration = corrupt_data("unrecognised");
  try {
    if (!storage["Kc"].empty() && !storage["Rp"].empty()) {
      loaded.format = CalibrationFormat::kSlStudio;
      calibration = read_slstudio(storage);
    } else {
      calibration = read_gvkit(storage);
    }
  } catch (const cv::Exception& e) {
    return corrupt_data(path.string() + ": cannot parse calibration: " + e.what());
  }
  if (!calibration.is_ok()) return calibration.status().with_context(path.string());
  loaded.calibration = *calibration;
  GVKIT_RETURN_IF_ERROR(loaded.calibration.check().with_context(path.string()));
  return loaded;
}

Status write_calibration(const fs::path& path, const Calibration& c) {
  GVKIT_RETURN_IF_ERROR(c.check().with_context(path.string()));
  const std::string ext = path.extension().string();
  if (ext != ".yaml" && ext != ".yml" && ext != ".json" && ext != ".xml")
    return unsupported(path.string() + ": calibration must be .yaml, .yml, .json or .xml");
  std::string text;
  try {
    cv::FileStorage storage(ext, cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    storage << "camera_K" << cv::Mat(c.camera_K);
    if (!c.camera_dist.empty()) storage << "camera_dist" << cv::Mat(c.camera_dist, true);
    storage << "camera_width" << c.camera_width << "camera_height" << c.camera_height;
    storage << "projector_K" << cv::Mat(c.projector_K);
    if (!c.projector_dist.empty()) storage << "projector_dist" << cv::Mat(c.projector_dist, true);
    storage << "projector_width" << c.projector_width << "projector_height" << c.projector_height;
    storage << "R_cam_from_proj" << cv::Mat(c.R_cam_from_proj);
    storage << "t_cam_from_proj_mm" << cv::Mat(c.t_cam_from_proj_mm);
    storage << "fringe_pitch_px" << c.fringe_pitch_px;
    storage << "camera_error_px" << c.camera_error_px;
    storage << "projector_error_px" << c.projector_error_px;
    storage << "stereo_error_px" << c.stereo_error_px;
    text = storage.releaseAndGetString();
  } catch (const cv::Exception& e) {
    return io_error(path.string() + ": cannot encode calibration: " + e.what());
  }
  return write_file_atomically(path, text);
}

}  // namespace gvkit
