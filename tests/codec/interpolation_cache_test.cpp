// ReferenceInterpolationCache: a hit hands back the object made for the same plane (and its
// predictions equal a freshly made InterpolatedReference's), changed samples at the same address
// or another margin make a new one, entries unused for two frames are dropped, and planes coded
// with the cache are byte for byte the ones coded without it (P planes with joint search and
// several references, B planes), the references being reused across planes.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "gvkit/codec/interpolation_cache.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {
namespace {

// A smooth 16-bit surface sampled at (x + dx, y + dy), with a little texture from `seed`.
SamplePlane smooth_plane(int size, double dx, double dy, int seed = 0) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = x + dx, v = y + dy;
      p.at(x, y) =
          static_cast<uint16_t>(std::lround(30000 + 9000 * std::sin(u * 0.21) * std::cos(v * 0.17) +
                                            40 * u - 25 * v + ((x * 7 + y * 13 + seed * 31) % 5)));
    }
  return p;
}

// Predictions of a few blocks and vectors (quarter and whole samples, inside and beyond the
// margin) from two interpolated references agree.
void expect_same_predictions(const InterpolatedReference& a, const InterpolatedReference& b) {
  int32_t pa[16 * 16], pb[16 * 16];
  for (int mv : {0, 5, -7, 13, -30, 90})
    for (bool qpel : {false, true}) {
      a.predict(16, 16, 16, 16, mv, -mv / 2, qpel, pa);
      b.predict(16, 16, 16, 16, mv, -mv / 2, qpel, pb);
      for (int i = 0; i < 16 * 16; ++i) ASSERT_EQ(pa[i], pb[i]) << "mv " << mv << " qpel " << qpel;
    }
}

TEST(InterpolationCache, HitReturnsTheSameObjectAndItPredictsAsAFreshOne) {
  ReferenceInterpolationCache cache;
  const SamplePlane ref = smooth_plane(64, 0, 0);
  const auto first = cache.get(ref, 16, 8);
  const auto second = cache.get(ref, 16, 8);
  EXPECT_EQ(first.get(), second.get());
  EXPECT_EQ(cache.made(), 1);
  EXPECT_EQ(cache.reused(), 1);
  expect_same_predictions(*second, InterpolatedReference(ref, 16, 8));
  // Another margin or bit depth of the same plane is another object.
  const auto wider = cache.get(ref, 16, 12);
  EXPECT_NE(wider.get(), first.get());
  EXPECT_EQ(cache.made(), 2);
  expect_same_predictions(*wider, InterpolatedReference(ref, 16, 12));
}

TEST(InterpolationCache, ChangedSamplesAtTheSameAddressAreInterpolatedAgain) {
  ReferenceInterpolationCache cache;
  SamplePlane ref = smooth_plane(64, 0, 0);
  const auto before = cache.get(ref, 16, 8);
  ref = smooth_plane(64, 1.5, -0.5);  // same object, new samples
  const auto after = cache.get(ref, 16, 8);
  EXPECT_NE(before.get(), after.get());
  EXPECT_EQ(cache.made(), 2);
  EXPECT_EQ(cache.reused(), 0);
  expect_same_predictions(*after, InterpolatedReference(ref, 16, 8));
  ref.at(10, 20) ^= 1;  // a single sample
  EXPECT_NE(cache.get(ref, 16, 8).get(), after.get());
  EXPECT_EQ(cache.made(), 3);
}

TEST(InterpolationCache, EntriesUnusedForTwoFramesAreDropped) {
  ReferenceInterpolationCache cache;
  const SamplePlane a = smooth_plane(32, 0, 0), b = smooth_plane(32, 2, 1);
  cache.get(a, 16, 4);
  cache.get(b, 16, 4);
  cache.next_frame();  // frame 0 ends: both were used in it
  EXPECT_EQ(cache.size(), 2u);
  cache.get(a, 16, 4);
  cache.next_frame();  // frame 1 ends: b unused in it, but used in frame 0: kept
  EXPECT_EQ(cache.size(), 2u);
  cache.get(a, 16, 4);
  cache.next_frame();  // frame 2 ends: b unused in frames 1 and 2
  EXPECT_EQ(cache.size(), 1u);
  EXPECT_EQ(cache.made(), 2);
  cache.get(b, 16, 4);
  EXPECT_EQ(cache.made(), 3);
}

TEST(InterpolationCache, PlanesCodedWithTheCacheAreByteIdentical) {
  const int size = 64;
  // Three planes of a P frame, their references 0 .. 2 (nearest first).
  std::vector<SamplePlane> cur, ref0, ref1, ref2;
  for (int j = 0; j < 3; ++j) {
    cur.push_back(smooth_plane(size, 1.25 + j, -0.5, j));
    ref0.push_back(smooth_plane(size, 0.5 + j, 0, j + 3));
    ref1.push_back(smooth_plane(size, j, 0.75, j + 6));
    ref2.push_back(smooth_plane(size, -0.25 + j, 1, j + 9));
  }
  PlaneCodingParams p;
  p.qp_prime = 40;
  p.subpel = 4;
  p.td_prediction = true;
  p.ref_count = 3;
  p.max_transform = 16;
  p.search_range = 4;
  for (bool rdo : {false, true}) {
    p.rdo = rdo;
    p.partitions = rdo;
    ReferenceInterpolationCache cache;
    for (int round = 0; round < 2; ++round) {  // the second round codes from cached objects only
      for (int i = 0; i < 3; ++i) {
        JointSearchPlanes joint;
        if (i == 0)
          for (int j = 1; j < 3; ++j) {
            joint.sources.push_back(&cur[j]);
            joint.references.push_back(&ref0[j]);
          }
        if (!joint.sources.empty()) {
          joint.more_references.push_back({&ref1[1], &ref1[2]});
          joint.more_references.push_back({&ref2[1], &ref2[2]});
        }
        const std::vector<const SamplePlane*> more = {&ref1[i], &ref2[i]};
        const PlaneEncodeResult plain =
            encode_plane(cur[i], p, &ref0[i], nullptr, &joint, &more, nullptr);
        const PlaneEncodeResult cached =
            encode_plane(cur[i], p, &ref0[i], nullptr, &joint, &more, nullptr, &cache);
        ASSERT_EQ(plain.bytes, cached.bytes) << "P plane " << i << " rdo " << rdo;
        EXPECT_EQ(plain.reconstruction.samples, cached.reconstruction.samples);
        // B plane from two of the same references.
        const PlaneEncodeResult b_plain = encode_b_plane(cur[i], p, ref1[i], ref0[i]);
        const PlaneEncodeResult b_cached =
            encode_b_plane(cur[i], p, ref1[i], ref0[i], nullptr, &cache);
        ASSERT_EQ(b_plain.bytes, b_cached.bytes) << "B plane " << i << " rdo " << rdo;
      }
      cache.next_frame();
    }
    // 9 references interpolated once each (margin search_range + 4); every other use is a hit.
    EXPECT_EQ(cache.made(), 9);
    EXPECT_GT(cache.reused(), 9);
  }
}

}  // namespace
}  // namespace gvkit::codec
