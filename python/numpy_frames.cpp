#include "numpy_frames.hpp"

#include <cmath>
#include <cstring>

namespace py = pybind11;

namespace gvkit::python {
namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

[[noreturn]] void bad_shape(const std::string& what, const std::string& expected,
                            const py::array& a) {
  throw py::value_error(what + ": shape " + shape_of(a) + ", expected " + expected);
}

}  // namespace

void raise_status(const Status& status) {
  const std::string& m = status.message();
  switch (status.code()) {
    case StatusCode::kInvalidArgument:
      throw py::value_error(m);
    case StatusCode::kNotFound:
      PyErr_SetString(PyExc_FileNotFoundError, m.c_str());
      throw py::error_already_set();
    case StatusCode::kIoError:
      PyErr_SetString(PyExc_OSError, m.c_str());
      throw py::error_already_set();
    default:
      throw std::runtime_error(m);  // RuntimeError
  }
}

py::array_t<float> xyz_array(const GeometryImage& image) {
  const int h = image.xyz_mm.rows, w = image.xyz_mm.cols;
  py::array_t<float> out({h, w, 3});
  float* dst = out.mutable_data();
  for (int y = 0; y < h; ++y)
    std::memcpy(dst + static_cast<size_t>(y) * w * 3, image.xyz_mm.ptr<float>(y),
                sizeof(float) * 3 * w);
  return out;
}

py::array_t<bool> valid_array(const GeometryImage& image) {
  const int h = image.domain_mask.rows, w = image.domain_mask.cols;
  py::array_t<bool> out({h, w});
  bool* dst = out.mutable_data();
  for (int y = 0; y < h; ++y) {
    const uint8_t* m = image.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) dst[static_cast<size_t>(y) * w + x] = m[x] != 0;
  }
  return out;
}

py::object texture_array(const GeometryImage& image) {
  if (image.texture.empty()) return py::none();
  const int h = image.texture.rows, w = image.texture.cols;
  py::array_t<float> out({h, w});
  for (int y = 0; y < h; ++y)
    std::memcpy(out.mutable_data() + static_cast<size_t>(y) * w, image.texture.ptr<float>(y),
                sizeof(float) * w);
  return out;
}

std::vector<GeometryImage> frames_from_arrays(const py::array& xyz_in, const py::object& valid_in,
                                              const py::object& texture_in) {
  using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
  Floats xyz = Floats::ensure(xyz_in);
  if (!xyz) throw py::value_error("xyz: not convertible to a float32 array");
  if (xyz.ndim() == 3)
    xyz = Floats::ensure(xyz.reshape({py::ssize_t{1}, xyz.shape(0), xyz.shape(1), xyz.shape(2)}));
  if (xyz.ndim() != 4 || xyz.shape(3) != 3 || xyz.shape(0) < 1 || xyz.shape(1) < 1 ||
      xyz.shape(2) < 1)
    bad_shape("xyz", "(frames, height, width, 3) or (height, width, 3)", xyz);
  const py::ssize_t n = xyz.shape(0), h = xyz.shape(1), w = xyz.shape(2);
  const float* p = xyz.data();
  std::vector<GeometryImage> frames(static_cast<size_t>(n));
  for (py::ssize_t f = 0; f < n; ++f) {
    GeometryImage& g = frames[static_cast<size_t>(f)];
    g.index = f;
    g.xyz_mm.create(static_cast<int>(h), static_cast<int>(w), CV_32FC3);
    std::memcpy(g.xyz_mm.data, p + f * h * w * 3, sizeof(float) * h * w * 3);
  }
  // The mask: given, or where every frame is finite.
  using Bytes = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;
  if (valid_in.is_none()) {
    cv::Mat mask(static_cast<int>(h), static_cast<int>(w), CV_8U, cv::Scalar(255));
    for (const GeometryImage& g : frames)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const cv::Vec3f v = g.xyz_mm.at<cv::Vec3f>(y, x);
          if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
            mask.at<uint8_t>(y, x) = 0;
        }
    for (GeometryImage& g : frames) g.domain_mask = mask;
  } else {
    Bytes valid = Bytes::ensure(valid_in);
    if (!valid) throw py::value_error("valid: not convertible to a boolean array");
    const bool per_frame = valid.ndim() == 3;
    if (!(valid.ndim() == 2 && valid.shape(0) == h && valid.shape(1) == w) &&
        !(per_frame && valid.shape(0) == n && valid.shape(1) == h && valid.shape(2) == w))
      bad_shape("valid", "(height, width) or (frames, height, width) of xyz", valid);
    for (py::ssize_t f = 0; f < n; ++f) {
      const uint8_t* m = valid.data() + (per_frame ? f * h * w : 0);
      cv::Mat mask(static_cast<int>(h), static_cast<int>(w), CV_8U);
      for (py::ssize_t k = 0; k < h * w; ++k) mask.data[k] = m[k] ? 255 : 0;
      frames[static_cast<size_t>(f)].domain_mask = mask;
    }
  }
  if (!texture_in.is_none()) {
    Floats texture = Floats::ensure(texture_in);
    if (!texture) throw py::value_error("texture: not convertible to a float32 array");
    const bool per_frame = texture.ndim() == 3;
    if (!(texture.ndim() == 2 && texture.shape(0) == h && texture.shape(1) == w) &&
        !(per_frame && texture.shape(0) == n && texture.shape(1) == h && texture.shape(2) == w))
      bad_shape("texture", "(height, width) or (frames, height, width) of xyz", texture);
    for (py::ssize_t f = 0; f < n; ++f) {
      cv::Mat t(static_cast<int>(h), static_cast<int>(w), CV_32F);
      std::memcpy(t.data, texture.data() + (per_frame ? f * h * w : 0), sizeof(float) * h * w);
      frames[static_cast<size_t>(f)].texture = t;
    }
  }
  return frames;
}

}  // namespace gvkit::python
