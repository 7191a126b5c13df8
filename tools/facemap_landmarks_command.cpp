// gvkit facemap landmarks MESH -o LANDMARKS.json [--image PNG]: 68 landmarks for a mesh that has
// none, from dlib on a frontal render of the mesh (its texture image when it has one), lifted
// back onto the surface (points_mm in the mesh file's frame and units, the input `facemap clean`
// takes with a mesh). The mesh is read as the file has it and repaired first (mesh_from_soup).
#include <cstdio>
#include <memory>
#include <string>

#include <opencv2/imgproc.hpp>

#include "command.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/mesh_from_soup.hpp"
#include "gvkit/facemap/mesh_landmarks.hpp"

namespace gvkit::tools {
namespace {

struct Options {
  std::string mesh, output, image, model = facemap::kDefaultShapePredictorPath;
  facemap::MeshLandmarkOptions landmarks;
};

void run(const Options& o) {
  throw_if_error(o.landmarks.check());
  const TriangleSoup soup = value_or_throw(read_triangle_soup(o.mesh));
  const facemap::SoupMesh repaired = value_or_throw(facemap::mesh_from_soup(soup, o.mesh));
  const Mesh& mesh = repaired.mesh;
  facemap::LandmarkDetectorOptions detector_options;
  detector_options.model_path = o.model;
  const auto detector = value_or_throw(facemap::LandmarkDetector::create(detector_options));
  const auto found = value_or_throw(
      facemap::detect_mesh_landmarks(mesh, detector, o.mesh, o.landmarks, &repaired.texture));
  throw_if_error(write_face_landmarks(o.output, found.landmarks));
  if (!o.image.empty()) {
    cv::Mat grey, colour;
    found.render.image.convertTo(grey, CV_8U, 255.0);
    cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
    for (const auto& p : found.landmarks.points_px)
      cv::circle(colour, p, 2, cv::Scalar(0, 0, 255), cv::FILLED);
    throw_if_error(write_image(o.image, colour));
  }
  std::printf(
      "%s: 68 landmarks (render %s, %dx%d px, %.3f mm/px, view %s, roll %d deg, %d moved onto "
      "the surface, %d out of cavities) -> %s\n",
      o.mesh.c_str(),
      found.render.textured   ? "texture"
      : found.render.coloured ? "vertex colours"
                              : "shaded",
      found.render.image.cols, found.render.image.rows, found.render.pixel_mm,
      found.view_name.c_str(), found.roll_deg, found.gap_filled, found.cavity_moved,
      o.output.c_str());
}

}  // namespace

void add_facemap_landmarks_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = facemap_group(app)->add_subcommand(
      "landmarks", "68 landmarks of a mesh from dlib on a frontal render (points_mm)");
  cmd->add_option("MESH", o->mesh, "Mesh (PLY/OBJ; the points are in its own units)")->required();
  cmd->add_option("-o,--output", o->output, "Landmarks JSON (e.g. frame_000000.landmarks.json)")
      ->required();
  cmd->add_option("--image", o->image, "Also write the render with the points (PNG)");
  cmd->add_option("--size", o->landmarks.render.size_px, "Render size, px")->capture_default_str();
  cmd->add_option("--max-gap", o->landmarks.max_gap_px,
                  "A point over a hole moves to the nearest rendered pixel up to this far, px")
      ->capture_default_str();
  cmd->add_option("--model", o->model, "dlib 68-point shape predictor")->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace gvkit::tools
