#include "gvkit/core/face_landmarks_io.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

TEST(FaceLandmarksIo, RoundTrip) {
  TempDir dir;
  FaceLandmarks l;
  for (int i = 0; i < 68; ++i) {
    l.points_px.emplace_back(i * 1.5f, 100 - i);
    l.points_mm.emplace_back(i, -i, 600 + 0.25f * i);
  }
  ASSERT_TRUE(write_face_landmarks(dir / "l.json", l).is_ok());
  auto back = read_face_landmarks(dir / "l.json");
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  ASSERT_EQ(back->points_px.size(), 68u);
  ASSERT_EQ(back->points_mm.size(), 68u);
  EXPECT_EQ(back->points_px[10], l.points_px[10]);
  EXPECT_EQ(back->points_mm[67], l.points_mm[67]);
}

TEST(FaceLandmarksIo, WrongCountIsRejected) {
  TempDir dir;
  ASSERT_TRUE(write_file_atomically(dir / "l.json", R"({"points_px": [[1, 2], [3, 4]]})").is_ok());
  auto bad = read_face_landmarks(dir / "l.json");
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("68"), std::string::npos);
}

}  // namespace
}  // namespace gvkit
