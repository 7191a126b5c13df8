// Landmark files of other tools: .npy (any numeric dtype, both orders), .txt/.csv/.pts rows,
// .json lists and gvkit's own JSON; 68 points or the 51 without the jaw (mapped to 17-67); bad
// files (wrong count, NaN, wrong shape, mixed rows) rejected naming the file.
#include "gvkit/core/landmark_points_io.hpp"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/npy_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::contains;
using testing::TempDir;

// Point i of a test set: distinct coordinates.
cv::Vec3d point(int i) { return {10.0 + i, 200.0 - 2 * i, 600.0 + 0.5 * i}; }

std::vector<double> flat(int count, int dims, int first = 0) {
  std::vector<double> v;
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < dims; ++k) v.push_back(point(first + i)[k % 3]);
  return v;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  ASSERT_TRUE(write_file_atomically(path, text).is_ok());
}

TEST(NpyIo, RoundTripAndForeignLayouts) {
  TempDir dir;
  const std::vector<double> values = flat(68, 3);
  for (NpyType type : {NpyType::kFloat64, NpyType::kFloat32}) {
    ASSERT_TRUE(write_npy(dir / "a.npy", {68, 3}, values, type).is_ok());
    auto back = read_npy(dir / "a.npy");
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    EXPECT_EQ(back->shape, (std::vector<size_t>{68, 3}));
    EXPECT_NEAR(back->values[3 * 40 + 2], values[3 * 40 + 2], 1e-4);
  }
  // Big-endian int16, Fortran order, shape (2, 3), written by hand.
  std::string header = "{'descr': '>i2', 'fortran_order': True, 'shape': (2, 3), }";
  header.append(128 - 10 - header.size() - 1, ' ');
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes += static_cast<char>(header.size());
  bytes += '\0';
  bytes += header;
  // Column-major: a[0,0], a[1,0], a[0,1], a[1,1], a[0,2], a[1,2] = 1, 4, 2, 5, 3, -6.
  for (int16_t v : {1, 4, 2, 5, 3, -6}) {
    bytes += static_cast<char>((v >> 8) & 0xff);
    bytes += static_cast<char>(v & 0xff);
  }
  write_text(dir / "f.npy", bytes);
  auto f = read_npy(dir / "f.npy");
  ASSERT_TRUE(f.is_ok()) << f.status().message();
  EXPECT_EQ(f->values, (std::vector<double>{1, 2, 3, 4, 5, -6}));
}

TEST(LandmarkPointsIo, EveryFormatGivesThe68PointNumbering) {
  TempDir dir;
  // 68 x 3 .npy, (1, 68, 3) float32 .npy, 51 x 2 .txt, .pts, .csv with a header, .json list,
  // .json object, gvkit's own JSON.
  ASSERT_TRUE(write_npy(dir / "a.npy", {68, 3}, flat(68, 3)).is_ok());
  ASSERT_TRUE(write_npy(dir / "b.npy", {1, 68, 3}, flat(68, 3), NpyType::kFloat32).is_ok());
  std::string txt = "# x y\n", pts = "version: 1\nn_points: 68\n{\n", csv = "x,y,z\n";
  std::string list = "[", object = R"({"landmarks": [)";
  for (int i = 0; i < 68; ++i) {
    const cv::Vec3d p = point(i);
    if (i >= 17) txt += std::to_string(p[0]) + "\t" + std::to_string(p[1]) + "\n";
    pts += std::to_string(p[0]) + " " + std::to_string(p[1]) + "\n";
    csv += std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + "\n";
    list += std::string(i ? "," : "") + "[" + std::to_string(p[0]) + "," + std::to_string(p[1]) +
            "," + std::to_string(p[2]) + "]";
    object +=
        std::string(i ? "," : "") + "[" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "]";
  }
  write_text(dir / "c.txt", txt);
  write_text(dir / "d.pts", pts + "}\n");
  write_text(dir / "e.csv", csv);
  write_text(dir / "f.json", list + "]");
  write_text(dir / "g.json", object + "]}");
  struct Case {
    const char* file;
    int dims, count;
  };
  for (const Case& c :
       {Case{"a.npy", 3, 68}, Case{"b.npy", 3, 68}, Case{"c.txt", 2, 51}, Case{"d.pts", 2, 68},
        Case{"e.csv", 3, 68}, Case{"f.json", 3, 68}, Case{"g.json", 2, 68}}) {
    SCOPED_TRACE(c.file);
    auto points = read_landmark_points(dir / c.file);
    ASSERT_TRUE(points.is_ok()) << points.status().message();
    EXPECT_EQ(points->dims, c.dims);
    EXPECT_EQ(points->file_count, c.count);
    ASSERT_EQ(points->points.size(), 68u);
    for (int i = 68 - c.count; i < 68; ++i)
      for (int k = 0; k < c.dims; ++k) ASSERT_NEAR(points->points[i][k], point(i)[k], 1e-3) << i;
    // A 51-point set has no jaw.
    EXPECT_EQ(std::isnan(points->points[8][0]), c.count == 51);
  }
  // gvkit's own JSON, with the jaw absent (null): both lists, chosen by dims.
  FaceLandmarks own;
  for (int i = 0; i < 68; ++i) {
    const cv::Vec3d p = i < 17 ? cv::Vec3d(NAN, NAN, NAN) : point(i);
    own.points_mm.emplace_back(cv::Vec3f(p));
    own.points_px.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
  }
  ASSERT_TRUE(write_face_landmarks(dir / "own.landmarks.json", own).is_ok());
  auto back = read_face_landmarks(dir / "own.landmarks.json");
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  EXPECT_TRUE(std::isnan(back->points_mm[3][0]));
  EXPECT_NEAR(back->points_mm[40][2], point(40)[2], 1e-3);
  auto mm = read_landmark_points(dir / "own.landmarks.json", 3);
  auto px = read_landmark_points(dir / "own.landmarks.json", 2);
  ASSERT_TRUE(mm.is_ok() && px.is_ok()) << mm.status().message() << px.status().message();
  EXPECT_EQ(mm->dims, 3);
  EXPECT_EQ(px->dims, 2);
  EXPECT_TRUE(std::isnan(mm->points[16][0]));
  const FaceLandmarks scaled = to_face_landmarks(*mm, 10.0);
  EXPECT_NEAR(scaled.points_mm[30][0], 10.0 * point(30)[0], 1e-2);
  EXPECT_EQ(scaled.chin_or_lower_lip_mm(), scaled.points_mm[57]);  // no chin: the lower lip
}

TEST(LandmarkPointsIo, BadFilesAreRejectedNamingTheFile) {
  TempDir dir;
  std::vector<double> with_nan = flat(68, 2);
  with_nan[2 * 33 + 1] = NAN;
  ASSERT_TRUE(write_npy(dir / "nan.npy", {68, 2}, with_nan).is_ok());
  ASSERT_TRUE(write_npy(dir / "count.npy", {60, 2}, flat(60, 2)).is_ok());
  ASSERT_TRUE(write_npy(dir / "shape.npy", {68, 4}, flat(68, 4)).is_ok());
  ASSERT_TRUE(write_npy(dir / "flat.npy", {136}, flat(68, 2)).is_ok());
  write_text(dir / "mixed.txt", "1 2\n3 4 5\n");
  write_text(dir / "word.txt", "1 2\n3 four\n");
  write_text(dir / "few.csv", "1,2\n3,4\n");
  write_text(dir / "null.json", R"({"landmarks": [[1, 2], null]})");
  write_text(dir / "empty.json", "{}");
  write_text(dir / "not.npy", "hello");
  write_text(dir / "a.xml", "<points/>");
  std::string jaw_null = R"({"points_mm": [)";
  for (int i = 0; i < 68; ++i)
    jaw_null += std::string(i ? "," : "") + (i == 40 ? "null" : "[1,2,3]");
  write_text(dir / "eye_null.json", jaw_null + "]}");
  struct Case {
    const char* file;
    const char* expect;
  };
  for (const Case& c : {Case{"nan.npy", "nan.npy: point 33 is not finite"},
                        Case{"count.npy", "count.npy: 60 points; 68 (iBUG) or 51"},
                        Case{"shape.npy", "shape.npy: array of shape (68, 4)"},
                        Case{"flat.npy", "flat.npy: array of shape (136,)"},
                        Case{"mixed.txt", "mixed.txt: line 2: 3 numbers after rows of 2"},
                        Case{"word.txt", "word.txt: line 2: 'four' is not a number"},
                        Case{"few.csv", "few.csv: 2 points"},
                        Case{"null.json", "null.json: landmarks: point 1 is not a list"},
                        Case{"empty.json", "empty.json: no points"},
                        Case{"not.npy", "not.npy: not a NumPy .npy file"},
                        Case{"eye_null.json", "points_mm: point 40 is missing"},
                        Case{"missing.txt", "missing.txt: no such file"},
                        Case{"a.xml", "unknown landmark format"}}) {
    auto points = read_landmark_points(dir / c.file);
    ASSERT_FALSE(points.is_ok()) << c.file;
    EXPECT_TRUE(contains(points.status().message(), c.expect))
        << c.file << ": " << points.status().message();
  }
}

}  // namespace
}  // namespace gvkit
