#pragma once
// Conversions of the Python module (python/gvkit_module.cpp): geometry images to and from numpy
// arrays, and Status to Python exceptions. Every function here needs the GIL.

#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::python {

// Raises the Python exception of `status` (contract: not ok): ValueError for an invalid
// argument, FileNotFoundError for not found, OSError for an I/O error, RuntimeError otherwise
// (corrupt or unsupported streams); the message is the Status's, which names the file.
[[noreturn]] void raise_status(const Status& status);

// (H, W, 3) float32 mm of image.xyz_mm (a copy).
pybind11::array_t<float> xyz_array(const GeometryImage& image);
// (H, W) bool: the domain mask (true inside the domain).
pybind11::array_t<bool> valid_array(const GeometryImage& image);
// (H, W) float32 in [0, 1], or None when the image has no texture.
pybind11::object texture_array(const GeometryImage& image);

// Geometry images of numpy input: `xyz` (N, H, W, 3) or one frame (H, W, 3), float mm; `valid`
// None (the pixels finite in every frame), (H, W) or (N, H, W), nonzero inside the domain;
// `texture` None or (N, H, W) / (H, W) in [0, 1]. ValueError naming the argument and the shape
// it has otherwise.
std::vector<GeometryImage> frames_from_arrays(const pybind11::array& xyz,
                                              const pybind11::object& valid,
                                              const pybind11::object& texture);

}  // namespace gvkit::python
