#pragma once
// Random sample planes for the codec kernels' equality tests (optimised against reference).

#include <cstddef>
#include <cstdint>
#include <random>

#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec::testing {

// A width x height plane of samples in 0..max_value: half the rows uniform noise, half
// extremes (0 and max_value) to reach the kernels' clipping and overflow bounds.
inline SamplePlane random_plane(int width, int height, int max_value, std::mt19937& rng) {
  SamplePlane p;
  p.width = width;
  p.height = height;
  p.samples.resize(static_cast<size_t>(width) * height);
  std::uniform_int_distribution<int> u(0, max_value);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p.at(x, y) = static_cast<uint16_t>(y % 4 < 2 ? u(rng) : ((x + y) % 3 ? max_value : 0));
  return p;
}

}  // namespace gvkit::codec::testing
