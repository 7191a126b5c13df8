#include "gvkit/core/calibration_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <optional>

#include <opencv2/core/persistence.hpp>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/file_extension.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

// The top-level keys of one or more calibration files, looked up exactly first, then ignoring
// case. A key found in several files is taken from the first.
class KeySource {
 public:
  static Result<KeySource> open(const std::vector<fs::path>& paths) {
    KeySource s;
    if (paths.empty()) return invalid_argument("no calibration file given");
    for (const fs::path& path : paths) {
      std::error_code ec;
      if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
      auto storage = std::make_unique<cv::FileStorage>();
      try {
        if (!storage->open(path.string(), cv::FileStorage::READ))
          return corrupt_data(path.string() + ": not an OpenCV YAML/JSON/XML file");
      } catch (const cv::Exception& e) {
        return corrupt_data(path.string() + ": cannot parse calibration: " + e.what());
      }
      cv::FileNode root = storage->root();
      if (!root.isMap()) return corrupt_data(path.string() + ": not a map of named fields");
      s.keys_.push_back(root.keys());
      s.storages_.push_back(std::move(storage));
      s.paths_.push_back(path);
    }
    return s;
  }

  // File index holding key (exact, else case-insensitive), or -1. `only` restricts to a file.
  int file_of(const std::string& key, int only = -1) const {
    for (int pass = 0; pass < 2; ++pass)
      for (size_t f = 0; f < keys_.size(); ++f) {
        if (only >= 0 && static_cast<int>(f) != only) continue;
        for (const std::string& k : keys_[f])
          if (pass == 0 ? k == key : ascii_lower(k) == ascii_lower(key)) return static_cast<int>(f);
      }
    return -1;
  }
  bool has(const std::string& key, int only = -1) const { return file_of(key, only) >= 0; }

  cv::FileNode node(const std::string& key, int only = -1) const {
    const int f = file_of(key, only);
    if (f < 0) return cv::FileNode();
    for (int pass = 0; pass < 2; ++pass)
      for (const std::string& k : keys_[f])
        if (pass == 0 ? k == key : ascii_lower(k) == ascii_lower(key)) return (*storages_[f])[k];
    return cv::FileNode();
  }

  std::string all_keys() const {
    std::string out;
    for (const auto& keys : keys_)
      for (const std::string& k : keys) out += (out.empty() ? "" : ", ") + k;
    return out.empty() ? "none" : out;
  }
  std::string names() const {
    std::string out;
    for (const fs::path& p : paths_) out += (out.empty() ? "" : " + ") + p.string();
    return out;
  }
  size_t file_count() const { return paths_.size(); }

 private:
  std::vector<std::unique_ptr<cv::FileStorage>> storages_;
  std::vector<fs::path> paths_;
  std::vector<std::vector<std::string>> keys_;
};

// Numbers of a node: an opencv-matrix, a (nested) list, or a single number.
Status collect_numbers(const cv::FileNode& node, std::vector<double>& out) {
  if (node.isInt() || node.isReal()) {
    out.push_back(node.real());
    return Status::ok();
  }
  if (node.isSeq()) {
    for (cv::FileNodeIterator it = node.begin(); it != node.end(); ++it)
      GVKIT_RETURN_IF_ERROR(collect_numbers(*it, out));
    return Status::ok();
  }
  if (node.isMap() && !node["data"].empty()) {
    cv::Mat m;
    node >> m;
    if (m.empty()) return corrupt_data("not a matrix");
    m.convertTo(m, CV_64F);
    m = m.reshape(1, 1);
    out.insert(out.end(), m.begin<double>(), m.end<double>());
    return Status::ok();
  }
  return corrupt_data("not a matrix or list of numbers");
}

// Reads key as `count` numbers (count 0: any number, possibly none).
Result<std::vector<double>> read_numbers(const KeySource& src, const std::string& key, int count,
                                         int only = -1) {
  cv::FileNode node = src.node(key, only);
  if (node.empty()) return corrupt_data("missing field " + key);
  std::vector<double> v;
  Status s;
  try {
    s = collect_numbers(node, v);
  } catch (const cv::Exception&) {
    s = corrupt_data("not a matrix");
  }
  if (!s) return corrupt_data("field " + key + " is " + s.message());
  if (count > 0 && static_cast<int>(v.size()) != count)
    return corrupt_data("field " + key + " must have " + std::to_string(count) + " entries, has " +
                        std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) return corrupt_data("field " + key + " has non-finite entries");
  return v;
}

cv::Matx33d matx33(const std::vector<double>& v) {
  cv::Matx33d m;
  for (int i = 0; i < 9; ++i) m.val[i] = v[i];
  return m;
}

// The rotation matrix (row-major) of a rotation vector (axis * angle, Rodrigues).
std::vector<double> rotation_from_vector(const std::vector<double>& r) {
  const double angle = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (angle < 1e-15) return {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const cv::Vec3d k(r[0] / angle, r[1] / angle, r[2] / angle);
  const cv::Matx33d K(0, -k[2], k[1], k[2], 0, -k[0], -k[1], k[0], 0);
  const cv::Matx33d R = cv::Matx33d::eye() + std::sin(angle) * K + (1 - std::cos(angle)) * (K * K);
  return std::vector<double>(R.val, R.val + 9);
}

// Drops an all-zero coefficient list: "0 0 0 0 0" means no distortion.
std::vector<double> normalised_distortion(std::vector<double> d) {
  bool all_zero = true;
  for (double x : d) all_zero = all_zero && x == 0.0;
  if (all_zero) d.clear();
  return d;
}

Result<std::vector<double>> read_distortion(const KeySource& src,
                                            const std::vector<std::string>& keys, int only = -1) {
  for (const std::string& key : keys) {
    if (!src.has(key, only)) continue;
    GVKIT_ASSIGN_OR_RETURN(std::vector<double> d, read_numbers(src, key, 0, only));
    if (!d.empty() && d.size() != 4 && d.size() != 5 && d.size() != 8 && d.size() != 12 &&
        d.size() != 14)
      return corrupt_data("field " + key + " must have 4, 5, 8, 12 or 14 coefficients, has " +
                          std::to_string(d.size()));
    return normalised_distortion(d);
  }
  return std::vector<double>();
}

// A size from a width and a height key, or from one [w, h] key; 0x0 when absent.
Result<cv::Size> read_size(const KeySource& src, const std::string& width_key,
                           const std::string& height_key, int only = -1) {
  if (height_key.empty()) {
    if (!src.has(width_key, only)) return cv::Size();
    GVKIT_ASSIGN_OR_RETURN(std::vector<double> v, read_numbers(src, width_key, 2, only));
    return cv::Size(static_cast<int>(v[0]), static_cast<int>(v[1]));
  }
  if (!src.has(width_key, only) && !src.has(height_key, only)) return cv::Size();
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> w, read_numbers(src, width_key, 1, only));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> h, read_numbers(src, height_key, 1, only));
  return cv::Size(static_cast<int>(w[0]), static_cast<int>(h[0]));
}

double read_real_or(const KeySource& src, const std::string& key, double fallback) {
  cv::FileNode node = src.node(key);
  return (!node.empty() && (node.isReal() || node.isInt())) ? node.real() : fallback;
}

// What a file of each layout holds beyond the two devices.
struct Parsed {
  TwoDeviceCalibration devices;
  double fringe_pitch_px = 0;
  double camera_error_px = -1, projector_error_px = -1, stereo_error_px = -1;
};

struct Layout {
  CalibrationFormat format;
  std::vector<std::string> signature;  // keys that identify it (all required)
  const char* description;
};

const std::vector<Layout>& layouts() {
  static const std::vector<Layout> all = {
      {CalibrationFormat::kGvkit,
       {"camera_K", "projector_K", "R_cam_from_proj", "t_cam_from_proj_mm"},
       "gvkit (camera_K, camera_dist, projector_K, projector_dist, R_cam_from_proj, "
       "t_cam_from_proj_mm, camera_width, camera_height, projector_width, projector_height)"},
      {CalibrationFormat::kSlStudio,
       {"Kc", "kc", "Kp", "kp", "Rp", "Tp"},
       "SLStudio (Kc, kc, Kp, kp, Rp, Tp, frameWidth, frameHeight, screenResX, screenResY)"},
      {CalibrationFormat::kProcam,
       {"cam_K", "proj_K", "R", "T"},
       "procam / scan3d-capture (cam_K, cam_kc, proj_K, proj_kc, R, T)"},
      {CalibrationFormat::kStereo,
       {"M1", "M2", "R", "T"},
       "OpenCV stereo_calib (M1, D1, M2, D2 [intrinsics.yml] + R, T [extrinsics.yml])"},
      {CalibrationFormat::kCameraFiles,
       {"camera_matrix", "R", "T"},
       "OpenCV calibration sample, one file per device (camera_matrix, distortion_coefficients, "
       "image_width, image_height; the camera's file first, the projector's second) + a file "
       "with R, T"},
  };
  return all;
}

Result<Parsed> parse_gvkit(const KeySource& src) {
  Parsed p;
  TwoDeviceCalibration& d = p.devices;
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> K1, read_numbers(src, "camera_K", 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> K2, read_numbers(src, "projector_K", 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> R, read_numbers(src, "R_cam_from_proj", 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> t, read_numbers(src, "t_cam_from_proj_mm", 3));
  GVKIT_ASSIGN_OR_RETURN(d.dist1, read_distortion(src, {"camera_dist"}));
  GVKIT_ASSIGN_OR_RETURN(d.dist2, read_distortion(src, {"projector_dist"}));
  GVKIT_ASSIGN_OR_RETURN(d.size1, read_size(src, "camera_width", "camera_height"));
  GVKIT_ASSIGN_OR_RETURN(d.size2, read_size(src, "projector_width", "projector_height"));
  d.K1 = matx33(K1);
  d.K2 = matx33(K2);
  // gvkit stores cam_from_proj (1_from_2).
  const cv::Matx33d R_cam_from_proj = matx33(R);
  d.R_2_from_1 = R_cam_from_proj.t();
  d.t_2_from_1_mm = -(R_cam_from_proj.t() * cv::Vec3d(t[0], t[1], t[2]));
  d.format = CalibrationFormat::kGvkit;
  p.fringe_pitch_px = read_real_or(src, "fringe_pitch_px", 0);
  p.camera_error_px = read_real_or(src, "camera_error_px", -1);
  p.projector_error_px = read_real_or(src, "projector_error_px", -1);
  p.stereo_error_px = read_real_or(src, "stereo_error_px", -1);
  return p;
}

// A layout that stores K1, dist1, K2, dist2 and R, T = 2_from_1 under the given keys.
Result<Parsed> parse_keyed(const KeySource& src, CalibrationFormat format, const char* K1_key,
                           std::vector<std::string> dist1_keys, const char* K2_key,
                           std::vector<std::string> dist2_keys, const char* R_key,
                           const char* T_key) {
  Parsed p;
  TwoDeviceCalibration& d = p.devices;
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> K1, read_numbers(src, K1_key, 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> K2, read_numbers(src, K2_key, 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> R, read_numbers(src, R_key, 0));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> T, read_numbers(src, T_key, 3));
  GVKIT_ASSIGN_OR_RETURN(d.dist1, read_distortion(src, dist1_keys));
  GVKIT_ASSIGN_OR_RETURN(d.dist2, read_distortion(src, dist2_keys));
  d.K1 = matx33(K1);
  d.K2 = matx33(K2);
  if (R.size() == 3) R = rotation_from_vector(R);  // a rotation vector, as some tools store
  if (R.size() != 9)
    return corrupt_data(std::string("field ") + R_key +
                        " must be a 3x3 rotation or a rotation vector, has " +
                        std::to_string(R.size()) + " entries");
  d.R_2_from_1 = matx33(R);
  d.t_2_from_1_mm = {T[0], T[1], T[2]};
  d.format = format;
  p.camera_error_px = read_real_or(src, "cam_error", -1);
  p.projector_error_px = read_real_or(src, "proj_error", -1);
  p.stereo_error_px = read_real_or(src, "stereo_error", -1);
  return p;
}

Result<Parsed> parse_slstudio(const KeySource& src) {
  GVKIT_ASSIGN_OR_RETURN(Parsed p, parse_keyed(src, CalibrationFormat::kSlStudio, "Kc", {"kc"},
                                               "Kp", {"kp"}, "Rp", "Tp"));
  GVKIT_ASSIGN_OR_RETURN(p.devices.size1, read_size(src, "frameWidth", "frameHeight"));
  GVKIT_ASSIGN_OR_RETURN(p.devices.size2, read_size(src, "screenResX", "screenResY"));
  return p;
}

Result<Parsed> parse_stereo(const KeySource& src) {
  GVKIT_ASSIGN_OR_RETURN(
      Parsed p, parse_keyed(src, CalibrationFormat::kStereo, "M1", {"D1"}, "M2", {"D2"}, "R", "T"));
  GVKIT_ASSIGN_OR_RETURN(cv::Size size, read_size(src, "imageSize", ""));
  p.devices.size1 = p.devices.size2 = size;
  for (auto [key, target] : {std::pair{"R1", &p.devices.R1}, std::pair{"R2", &p.devices.R2},
                             std::pair{"P1", &p.devices.P1}, std::pair{"P2", &p.devices.P2},
                             std::pair{"Q", &p.devices.Q}}) {
    if (!src.has(key)) continue;
    const int count = key[0] == 'R' ? 9 : key[0] == 'P' ? 12 : 16;
    GVKIT_ASSIGN_OR_RETURN(std::vector<double> v, read_numbers(src, key, count));
    *target = cv::Mat(v, true).reshape(1, key[0] == 'Q' ? 4 : 3);
  }
  return p;
}

// One device per file in OpenCV's calibration-sample layout, plus R, T from any file.
Result<Parsed> parse_camera_files(const KeySource& src) {
  std::vector<int> device_files;
  for (int f = 0; f < static_cast<int>(src.file_count()); ++f)
    if (src.has("camera_matrix", f) || src.has("cameraMatrix", f)) device_files.push_back(f);
  if (device_files.size() != 2)
    return corrupt_data(
        "the OpenCV calibration-sample layout needs two device files (camera, "
        "then projector) with camera_matrix, found " +
        std::to_string(device_files.size()));
  Parsed p;
  TwoDeviceCalibration& d = p.devices;
  for (int i = 0; i < 2; ++i) {
    const int f = device_files[i];
    const std::string K_key = src.has("camera_matrix", f) ? "camera_matrix" : "cameraMatrix";
    GVKIT_ASSIGN_OR_RETURN(std::vector<double> K, read_numbers(src, K_key, 9, f));
    GVKIT_ASSIGN_OR_RETURN(std::vector<double> dist,
                           read_distortion(src, {"distortion_coefficients", "distCoeffs"}, f));
    GVKIT_ASSIGN_OR_RETURN(cv::Size size, read_size(src, "image_width", "image_height", f));
    if (size.area() == 0) {
      GVKIT_ASSIGN_OR_RETURN(size, read_size(src, "imageWidth", "imageHeight", f));
    }
    (i == 0 ? d.K1 : d.K2) = matx33(K);
    (i == 0 ? d.dist1 : d.dist2) = dist;
    (i == 0 ? d.size1 : d.size2) = size;
  }
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> R, read_numbers(src, "R", 9));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> T, read_numbers(src, "T", 3));
  d.R_2_from_1 = matx33(R);
  d.t_2_from_1_mm = {T[0], T[1], T[2]};
  d.format = CalibrationFormat::kCameraFiles;
  return p;
}

// Picks the layout whose identifying keys are all present; otherwise names the nearest layout's
// missing key, or every key found and every layout expected.
Result<Parsed> parse_any(const KeySource& src) {
  const Layout* best = nullptr;
  double best_share = 0;
  for (const Layout& layout : layouts()) {
    int found = 0;
    for (const std::string& key : layout.signature) found += src.has(key);
    const double share = static_cast<double>(found) / layout.signature.size();
    if (share > best_share) {
      best_share = share;
      best = &layout;
    }
  }
  if (best && best_share == 1.0) {
    try {
      switch (best->format) {
        case CalibrationFormat::kGvkit:
          return parse_gvkit(src);
        case CalibrationFormat::kSlStudio:
          return parse_slstudio(src);
        case CalibrationFormat::kProcam:
          return parse_keyed(src, CalibrationFormat::kProcam, "cam_K", {"cam_kc", "cam_dist"},
                             "proj_K", {"proj_kc", "proj_dist"}, "R", "T");
        case CalibrationFormat::kStereo:
          return parse_stereo(src);
        case CalibrationFormat::kCameraFiles:
          return parse_camera_files(src);
      }
    } catch (const cv::Exception& e) {
      return corrupt_data(std::string("cannot parse calibration: ") + e.what());
    }
  }
  if (best && best_share >= 0.5) {
    std::string missing;
    for (const std::string& key : best->signature)
      if (!src.has(key)) missing += (missing.empty() ? "" : ", ") + key;
    return corrupt_data("missing field " + missing + " of the " + best->description +
                        " layout; keys found: " + src.all_keys());
  }
  std::string expected;
  for (const Layout& layout : layouts())
    expected += std::string(expected.empty() ? "" : "; ") + layout.description;
  return corrupt_data("unknown calibration layout; keys found: " + src.all_keys() +
                      "; expected one of: " + expected);
}

Result<Parsed> read_parsed(const std::vector<fs::path>& paths,
                           const CalibrationReadOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(KeySource src, KeySource::open(paths));
  Result<Parsed> parsed = parse_any(src);
  if (!parsed) return parsed.status().with_context(src.names());
  parsed->devices.t_2_from_1_mm *= options.length_unit_mm;
  return parsed;
}

}  // namespace

const char* calibration_format_name(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kGvkit:
      return "gvkit";
    case CalibrationFormat::kSlStudio:
      return "SLStudio";
    case CalibrationFormat::kProcam:
      return "procam";
    case CalibrationFormat::kStereo:
      return "stereo";
    case CalibrationFormat::kCameraFiles:
      return "camera";
  }
  return "unknown";
}

Status CalibrationReadOptions::check() const {
  if (camera_size.width < 0 || camera_size.height < 0 || projector_size.width < 0 ||
      projector_size.height < 0)
    return invalid_argument("calibration device sizes must not be negative");
  if (!(length_unit_mm > 0) || !std::isfinite(length_unit_mm))
    return invalid_argument("calibration length unit must be a positive number of mm");
  return Status::ok();
}

Result<LoadedCalibration> read_calibration(const fs::path& path,
                                           const CalibrationReadOptions& options) {
  return read_calibration(std::vector<fs::path>{path}, options);
}

Result<LoadedCalibration> read_calibration(const std::vector<fs::path>& paths,
                                           const CalibrationReadOptions& options) {
  GVKIT_ASSIGN_OR_RETURN(Parsed p, read_parsed(paths, options));
  std::string names;
  for (const fs::path& path : paths) names += (names.empty() ? "" : " + ") + path.string();
  const TwoDeviceCalibration& d = p.devices;
  const std::string layout = std::string(" (") + calibration_format_name(d.format) + " layout)";
  LoadedCalibration loaded;
  loaded.format = d.format;
  Calibration& c = loaded.calibration;
  c.camera_K = d.K1;
  c.camera_dist = d.dist1;
  c.projector_K = d.K2;
  c.projector_dist = d.dist2;
  c.R_cam_from_proj = d.R_2_from_1.t();
  c.t_cam_from_proj_mm = -(d.R_2_from_1.t() * d.t_2_from_1_mm);
  // The stereo layout's imageSize is the cameras' size, never a projector's.
  const cv::Size projector_in_file = d.format == CalibrationFormat::kStereo ? cv::Size() : d.size2;
  cv::Size camera = d.size1, projector = projector_in_file;
  if (camera.area() == 0) {
    loaded.camera_size_from_file = false;
    camera = options.camera_size;
    if (camera.area() == 0)
      return invalid_argument(names + layout +
                              ": no camera image size in the file; it is taken from the images "
                              "when reading a folder of fringe images");
  }
  if (projector.area() == 0) {
    loaded.projector_size_from_file = false;
    projector = options.projector_size;
    if (projector.area() == 0)
      return invalid_argument(names + layout +
                              ": no projector size in the file; give it with --projector-size WxH "
                              "(the projector's pixels, e.g. 912x570)");
  } else if (options.projector_size.area() > 0 && options.projector_size != projector) {
    return invalid_argument(names + ": records a " + size_text(projector) +
                            " projector, but --projector-size says " +
                            size_text(options.projector_size));
  }
  c.camera_width = camera.width;
  c.camera_height = camera.height;
  c.projector_width = projector.width;
  c.projector_height = projector.height;
  c.fringe_pitch_px = p.fringe_pitch_px;
  c.camera_error_px = p.camera_error_px;
  c.projector_error_px = p.projector_error_px;
  c.stereo_error_px = p.stereo_error_px;
  GVKIT_RETURN_IF_ERROR(c.check().with_context(names));
  return loaded;
}

Result<TwoDeviceCalibration> read_two_device_calibration(const std::vector<fs::path>& paths,
                                                         const CalibrationReadOptions& options) {
  GVKIT_ASSIGN_OR_RETURN(Parsed p, read_parsed(paths, options));
  TwoDeviceCalibration& d = p.devices;
  if (d.size1.area() == 0) d.size1 = options.camera_size;
  if (d.size2.area() == 0) d.size2 = options.camera_size;
  return d;
}

Status write_calibration(const fs::path& path, const Calibration& c) {
  return write_calibration(path, c, CalibrationFormat::kGvkit);
}

Status write_calibration(const fs::path& path, const Calibration& c, CalibrationFormat format) {
  GVKIT_RETURN_IF_ERROR(c.check().with_context(path.string()));
  const std::string ext = path.extension().string();
  if (ext != ".yaml" && ext != ".yml" && ext != ".json" && ext != ".xml")
    return unsupported(path.string() + ": calibration must be .yaml, .yml, .json or .xml");
  if (format == CalibrationFormat::kCameraFiles)
    return unsupported(path.string() + ": the one-file-per-device layout is not written");
  const cv::Matx33d R_proj_from_cam = c.R_proj_from_cam();
  const cv::Vec3d t_proj_from_cam = c.t_proj_from_cam_mm();
  auto dist = [](const std::vector<double>& d) {
    return d.empty() ? cv::Mat(cv::Mat::zeros(1, 5, CV_64F)) : cv::Mat(d, true).reshape(1, 1);
  };
  std::string text;
  try {
    cv::FileStorage storage(ext, cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    switch (format) {
      case CalibrationFormat::kGvkit:
        storage << "camera_K" << cv::Mat(c.camera_K);
        if (!c.camera_dist.empty()) storage << "camera_dist" << cv::Mat(c.camera_dist, true);
        storage << "camera_width" << c.camera_width << "camera_height" << c.camera_height;
        storage << "projector_K" << cv::Mat(c.projector_K);
        if (!c.projector_dist.empty())
          storage << "projector_dist" << cv::Mat(c.projector_dist, true);
        storage << "projector_width" << c.projector_width << "projector_height"
                << c.projector_height;
        storage << "R_cam_from_proj" << cv::Mat(c.R_cam_from_proj);
        storage << "t_cam_from_proj_mm" << cv::Mat(c.t_cam_from_proj_mm);
        storage << "fringe_pitch_px" << c.fringe_pitch_px;
        storage << "camera_error_px" << c.camera_error_px;
        storage << "projector_error_px" << c.projector_error_px;
        storage << "stereo_error_px" << c.stereo_error_px;
        break;
      case CalibrationFormat::kSlStudio:
        storage << "Kc" << cv::Mat(c.camera_K) << "kc" << dist(c.camera_dist);
        storage << "Kp" << cv::Mat(c.projector_K) << "kp" << dist(c.projector_dist);
        storage << "Rp" << cv::Mat(R_proj_from_cam) << "Tp" << cv::Mat(t_proj_from_cam);
        storage << "cam_error" << c.camera_error_px << "proj_error" << c.projector_error_px
                << "stereo_error" << c.stereo_error_px;
        storage << "frameWidth" << c.camera_width << "frameHeight" << c.camera_height;
        storage << "screenResX" << c.projector_width << "screenResY" << c.projector_height;
        break;
      case CalibrationFormat::kProcam:
        storage << "cam_K" << cv::Mat(c.camera_K) << "cam_kc" << dist(c.camera_dist);
        storage << "proj_K" << cv::Mat(c.projector_K) << "proj_kc" << dist(c.projector_dist);
        storage << "R" << cv::Mat(R_proj_from_cam) << "T" << cv::Mat(t_proj_from_cam);
        storage << "cam_error" << c.camera_error_px << "proj_error" << c.projector_error_px
                << "stereo_error" << c.stereo_error_px;
        break;
      case CalibrationFormat::kStereo:
        storage << "M1" << cv::Mat(c.camera_K) << "D1" << dist(c.camera_dist);
        storage << "M2" << cv::Mat(c.projector_K) << "D2" << dist(c.projector_dist);
        storage << "R" << cv::Mat(R_proj_from_cam) << "T" << cv::Mat(t_proj_from_cam);
        break;
      case CalibrationFormat::kCameraFiles:
        break;
    }
    text = storage.releaseAndGetString();
  } catch (const cv::Exception& e) {
    return io_error(path.string() + ": cannot encode calibration: " + e.what());
  }
  return write_file_atomically(path, text);
}

}  // namespace gvkit
