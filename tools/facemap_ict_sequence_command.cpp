// gvkit facemap ict-sequence ICT_DIR -o FACES [--frames N]: writes an ICT-FaceKit expression
// sequence as face frames in the contract of `facemap map` (frame_NNNNNN.ply: the face area,
// 4 boundary loops, mm, grey vertex colour; frame_NNNNNN.landmarks.json: the 68 landmark
// vertices). Every frame has the same vertex order, so correspondence is exact
// (`facemap map --same-vertices`).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "command.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/mesh_io.hpp"

namespace gvkit::tools {
namespace {

struct Options {
  std::string ict_dir, output;
  int frames = 10;
};

void run(const Options& o) {
  if (o.frames < 1 || o.frames > 10000)
    throw CommandFailed(invalid_argument("--frames must be in 1..10000"));
  const std::vector<std::string> names = {"jawOpen",       "mouthSmile_L",  "mouthSmile_R",
                                          "browInnerUp_L", "browInnerUp_R", "eyeBlink_L",
                                          "eyeBlink_R"};
  const IctFaceModel model = value_or_throw(IctFaceModel::load(o.ict_dir, names));
  throw_if_error(ensure_directory(o.output));
  for (int k = 0; k < o.frames; ++k) {
    // Talk-and-smile: the jaw opens and closes, a smile builds up, the brows rise once.
    const double t = o.frames > 1 ? static_cast<double>(k) / (o.frames - 1) : 0.0;
    const double jaw = 0.4 * std::sin(M_PI * t), smile = 0.5 * t,
                 brow = 0.5 * std::pow(std::sin(M_PI * t), 2);
    const auto positions = model.evaluate({{"jawOpen", jaw},
                                           {"mouthSmile_L", smile},
                                           {"mouthSmile_R", smile},
                                           {"browInnerUp_L", brow},
                                           {"browInnerUp_R", brow}});
    Mesh mesh = model.face_mesh(positions);
    mesh.request_vertex_colors();
    for (auto v : mesh.vertices()) {
      // Shade by depth so the texture channel carries something face-like.
      const float g = static_cast<float>(std::clamp(0.3 + 0.006 * mesh.point(v)[2], 0.0, 1.0));
      mesh.set_color(v, Mesh::Color(g, g, g, 1.f));
    }
    FaceLandmarks landmarks;
    for (int v : model.landmark_vertices())
      landmarks.points_mm.emplace_back(positions[v][0], positions[v][1], positions[v][2]);
    throw_if_error(write_mesh(frame_path(o.output, k, ".ply"), mesh));
    throw_if_error(write_face_landmarks(frame_path(o.output, k, ".landmarks.json"), landmarks));
  }
  std::printf("%s: %d ICT face frames\n", o.output.c_str(), o.frames);
}

}  // namespace

void add_facemap_ict_sequence_command(CLI::App& app) {
  auto* cmd = facemap_group(app)->add_subcommand(
      "ict-sequence", "Write an ICT-FaceKit expression sequence as face frames (PLY + landmarks)");
  auto o = std::make_shared<Options>();
  cmd->add_option("ict_dir", o->ict_dir, "ICT-FaceKit folder")->required();
  cmd->add_option("-o,--output", o->output, "Output folder")->required();
  cmd->add_option("--frames", o->frames, "Number of frames")->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace gvkit::tools
