// The decoder's optimised kernels (AVX2 where the processor has it) return exactly what their
// plain reference versions return, on random input and at the extremes of the sample range:
// half-resolution upsampling and dequantization to millimetres.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/half_resolution.hpp"

namespace gvkit::codec {
namespace {

SamplePlane random_plane(int width, int height, int max_value, std::mt19937& rng) {
  SamplePlane p;
  p.width = width;
  p.height = height;
  p.samples.resize(static_cast<size_t>(width) * height);
  std::uniform_int_distribution<int> u(0, max_value);
  // Half the rows noise, half extremes (0 and max) to reach the clipping and overflow bounds.
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p.at(x, y) = static_cast<uint16_t>(y % 4 < 2 ? u(rng) : ((x + y) % 3 ? max_value : 0));
  return p;
}

int padded(int n) { return (n + 15) / 16 * 16; }

TEST(DecoderKernels, UpsampleHalfPlaneEqualsTheReference) {
  std::mt19937 rng(11);
  // Even and odd sizes, a plane narrower than one vector, and every bit depth's clamp.
  const int sizes[][2] = {{320, 320}, {33, 17}, {7, 5}, {64, 1}, {1, 9}, {250, 62}};
  for (const auto& size : sizes)
    for (const int bit_depth : {8, 12, 16}) {
      const int width = size[0], height = size[1];
      const SamplePlane half = random_plane(padded(half_size(width)), padded(half_size(height)),
                                            (1 << bit_depth) - 1, rng);
      const SamplePlane fast = upsample_half_plane(half, width, height, bit_depth);
      const SamplePlane plain = upsample_half_plane_reference(half, width, height, bit_depth);
      ASSERT_EQ(fast.width, plain.width);
      ASSERT_EQ(fast.height, plain.height);
      ASSERT_EQ(fast.samples, plain.samples) << width << "x" << height << ", " << bit_depth;
    }
}

TEST(DecoderKernels, DequantizeGeometryEqualsTheReference) {
  std::mt19937 rng(12);
  for (const bool texture : {false, true})
    for (const int size : {320, 37, 5}) {
      SequenceInfo info;
      info.width = info.height = size;
      info.bit_depth = 16;
      info.has_texture = texture;
      info.box_min_mm = cv::Vec3d(-66.8115, -112.3237, 613.4776);
      info.box_max_mm = cv::Vec3d(74.5544, 88.4242, 712.1782);
      info.domain_mask = cv::Mat(size, size, CV_8U, cv::Scalar(255));
      std::vector<SamplePlane> planes;
      for (int a = 0; a < (texture ? 4 : 3); ++a)
        planes.push_back(random_plane(padded(size), padded(size), a < 3 ? 65535 : 255, rng));
      const GeometryImage fast = dequantize_geometry(planes, info, 3);
      const GeometryImage plain = dequantize_geometry_reference(planes, info, 3);
      ASSERT_EQ(fast.xyz_mm.size(), plain.xyz_mm.size());
      EXPECT_EQ(0, std::memcmp(fast.xyz_mm.data, plain.xyz_mm.data,
                               plain.xyz_mm.total() * plain.xyz_mm.elemSize()))
          << size;
      ASSERT_EQ(fast.texture.empty(), !texture);
      if (texture) {
        EXPECT_EQ(0, std::memcmp(fast.texture.data, plain.texture.data,
                                 plain.texture.total() * plain.texture.elemSize()));
      }
      EXPECT_EQ(fast.index, 3);
      EXPECT_EQ(fast.timestamp, plain.timestamp);
    }
}

}  // namespace
}  // namespace gvkit::codec
