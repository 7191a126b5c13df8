#include "gvkit/capture/synthetic_board.hpp"

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "gvkit/capture/session_writer.hpp"

namespace gvkit::capture {
namespace {

void add_quad(SyntheticScene& s, double x0, double y0, double x1, double y1, float albedo) {
  const int base = static_cast<int>(s.positions_mm.size());
  s.positions_mm.insert(s.positions_mm.end(), {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}});
  s.albedo.insert(s.albedo.end(), 4, albedo);
  s.triangles.emplace_back(base, base + 1, base + 2);
  s.triangles.emplace_back(base, base + 2, base + 3);
}

}  // namespace

SyntheticScene checkerboard_scene(const CalibrationBoard& board) {
  SyntheticScene s;
  const double q = board.square_mm;
  const int nx = board.inner_corners_x + 1, ny = board.inner_corners_y + 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      add_quad(s, (i - 1) * q, (j - 1) * q, i * q, j * q, ((i + j) % 2) ? 0.85f : 0.2f);
  // Margin: four light strips around the squares.
  const double x0 = -q, y0 = -q, x1 = (nx - 1) * q, y1 = (ny - 1) * q;
  add_quad(s, x0 - q, y0 - q, x1 + q, y0, 0.85f);
  add_quad(s, x0 - q, y1, x1 + q, y1 + q, 0.85f);
  add_quad(s, x0 - q, y0, x0, y1, 0.85f);
  add_quad(s, x1, y0, x1 + q, y1, 0.85f);
  return s;
}

Result<std::vector<FringeSet>> render_calibration_captures(
    const Calibration& truth, const CalibrationBoard& board,
    const ProjectorCalibrationOptions& options, const RenderOptions& render, int poses,
    uint64_t seed) {
  GVKIT_RETURN_IF_ERROR(board.check());
  GVKIT_ASSIGN_OR_RETURN(std::vector<cv::Mat> patterns, calibration_patterns(options));
  const SyntheticScene flat = checkerboard_scene(board);
  const cv::Vec3d centre((board.inner_corners_x - 1) * board.square_mm / 2,
                         (board.inner_corners_y - 1) * board.square_mm / 2, 0);
  // Tilts (degrees about x, y, z) and offsets (mm) of the poses.
  const double table[12][6] = {
      {-22, 0, 3, 0, 0, 650},    {22, 0, -4, 10, 0, 640},    {0, -25, 2, 0, 10, 660},
      {0, 25, -3, -10, 0, 650},  {15, 15, 5, 0, -10, 620},   {-15, -20, -6, 5, 5, 680},
      {10, -10, 8, -15, 5, 700}, {-10, 12, -8, 15, -5, 610}, {18, -5, 0, 0, 0, 630},
      {-5, 18, 4, 0, 8, 670},    {5, -18, -2, 8, 0, 690},    {-18, 5, 6, -8, -8, 600}};
  SyntheticRenderer renderer(truth, render);
  std::vector<FringeSet> captures;
  for (int p = 0; p < std::min(poses, 12); ++p) {
    const double* pose = table[p];
    cv::Matx33d rx, ry, rz;
    cv::Rodrigues(cv::Vec3d(pose[0] * CV_PI / 180, 0, 0), rx);
    cv::Rodrigues(cv::Vec3d(0, pose[1] * CV_PI / 180, 0), ry);
    cv::Rodrigues(cv::Vec3d(0, 0, pose[2] * CV_PI / 180), rz);
    const cv::Matx33d R = rz * ry * rx;
    SyntheticScene scene = flat;
    for (auto& v : scene.positions_mm) v = R * (v - centre) + cv::Vec3d(pose[3], pose[4], pose[5]);
    const SyntheticFrame frame = renderer.render(scene, patterns, seed * 131 + p);
    FringeSet f;
    f.images = frame.images;
    f.index = p;
    captures.push_back(std::move(f));
  }
  return captures;
}

Status write_board_session(const std::filesystem::path& dir, const Calibration& truth,
                           const CalibrationBoard& board,
                           const ProjectorCalibrationOptions& options, const RenderOptions& render,
                           int poses, uint64_t seed) {
  GVKIT_RETURN_IF_ERROR(render.check());
  GVKIT_ASSIGN_OR_RETURN(auto captures,
                         render_calibration_captures(truth, board, options, render, poses, seed));
  SessionInfo info;
  info.pattern = options.pattern;
  info.images_per_frame = static_cast<int>(captures.front().images.size());
  info.width = truth.camera_width;
  info.height = truth.camera_height;
  info.bit_depth = render.bit_depth;
  info.source = {{"kind", "calibration"},
                 {"board", {board.inner_corners_x, board.inner_corners_y}},
                 {"square_mm", board.square_mm},
                 {"images", "white, vertical fringes, horizontal fringes"}};
  GVKIT_ASSIGN_OR_RETURN(auto writer, SessionWriter::create(dir, info, truth));
  for (const FringeSet& f : captures) GVKIT_RETURN_IF_ERROR(writer->append(f));
  return Status::ok();
}

}  // namespace gvkit::capture
