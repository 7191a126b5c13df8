// gvkit facemap ict-sequence ICT_DIR -o FACES [--frames N] [--program P]: writes an ICT-FaceKit
// expression sequence as face frames in the contract of `facemap map` (frame_NNNNNN.ply: the face
// area, 4 boundary loops, mm, grey vertex colour; frame_NNNNNN.landmarks.json: the 68 landmark
// vertices) and sequence.json (each frame's blendshape weights). Every frame has the same vertex
// order, so correspondence is exact (`facemap map --same-vertices`). Programs: talk (the jaw
// opens and closes, a smile builds up, the brows rise once), expressions (neutral, then every
// expression of the folder at full weight, one frame each), tour (every expression in turn rises
// from neutral to full weight and falls back, over --frames frames).
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
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"

namespace gvkit::tools {
namespace {

struct Options {
  std::string ict_dir, output;
  int frames = 10;
  std::string program = "talk";
};

using Weights = std::map<std::string, double>;

// The blendshape weights of every frame of the program.
std::vector<Weights> program_weights(const Options& o, const IctFaceModel& model) {
  std::vector<Weights> out;
  if (o.program == "talk") {
    for (int k = 0; k < o.frames; ++k) {
      const double t = o.frames > 1 ? static_cast<double>(k) / (o.frames - 1) : 0.0;
      const double jaw = 0.4 * std::sin(M_PI * t), smile = 0.5 * t,
                   brow = 0.5 * std::pow(std::sin(M_PI * t), 2);
      out.push_back({{"jawOpen", jaw},
                     {"mouthSmile_L", smile},
                     {"mouthSmile_R", smile},
                     {"browInnerUp_L", brow},
                     {"browInnerUp_R", brow}});
    }
  } else if (o.program == "expressions") {
    out.push_back({});
    for (const auto& name : model.expression_names()) out.push_back({{name, 1.0}});
  } else {
    // tour: expression e takes frames [e F / E, (e + 1) F / E) and rises and falls as sin(pi u).
    const auto names = model.expression_names();
    const int count = static_cast<int>(names.size());
    for (int k = 0; k < o.frames; ++k) {
      const double t = static_cast<double>(k) * count / o.frames;
      const int e = std::min(count - 1, static_cast<int>(t));
      const double u = t - e;
      out.push_back({{names[e], std::sin(M_PI * u)}});
    }
  }
  return out;
}

void run(const Options& o) {
  if (o.frames < 1 || o.frames > 10000)
    throw CommandFailed(invalid_argument("--frames must be in 1..10000"));
  if (o.program != "talk" && o.program != "expressions" && o.program != "tour")
    throw CommandFailed(
        invalid_argument("--program must be talk, expressions or tour, got " + o.program));
  const std::vector<std::string> talk = {"jawOpen",       "mouthSmile_L",  "mouthSmile_R",
                                         "browInnerUp_L", "browInnerUp_R", "eyeBlink_L",
                                         "eyeBlink_R"};
  // talk needs its seven expressions; the others take every expression in the folder.
  const IctFaceModel model = value_or_throw(
      IctFaceModel::load(o.ict_dir, o.program == "talk" ? talk : std::vector<std::string>{}));
  if (o.program == "tour" && o.frames < static_cast<int>(model.expression_names().size()))
    throw CommandFailed(invalid_argument(
        "--program tour needs --frames >= " + std::to_string(model.expression_names().size()) +
        " (one or more per expression)"));
  throw_if_error(ensure_directory(o.output));
  const std::vector<Weights> frames = program_weights(o, model);
  nlohmann::json sequence = {{"ict_dir", o.ict_dir}, {"program", o.program}};
  nlohmann::json per_frame = nlohmann::json::array();
  for (size_t k = 0; k < frames.size(); ++k) {
    // One triangulation for every frame (the neutral face's quad diagonals: the shorter one of
    // an expression's quad may be the other), so all frames share one vertex layout.
    const auto positions = model.evaluate(frames[k]);
    std::vector<int> original;
    Mesh mesh = model.triangle_mesh(
        model.neutral_mm(), [](int v) { return v < IctFaceModel::kFaceVertexCount; }, &original);
    for (auto v : mesh.vertices()) {
      const cv::Vec3d& p = positions[original[v.idx()]];
      mesh.set_point(v, Mesh::Point(p[0], p[1], p[2]));
    }
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
    per_frame.push_back({{"index", k}, {"weights", frames[k]}});
  }
  sequence["frames"] = per_frame;
  throw_if_error(write_json(std::filesystem::path(o.output) / "sequence.json", sequence));
  std::printf("%s: %zu ICT face frames (%s)\n", o.output.c_str(), frames.size(), o.program.c_str());
}

}  // namespace

void add_facemap_ict_sequence_command(CLI::App& app) {
  auto* cmd = facemap_group(app)->add_subcommand(
      "ict-sequence", "Write an ICT-FaceKit expression sequence as face frames (PLY + landmarks)");
  auto o = std::make_shared<Options>();
  cmd->add_option("ict_dir", o->ict_dir, "ICT-FaceKit folder")->required();
  cmd->add_option("-o,--output", o->output, "Output folder")->required();
  cmd->add_option("--frames", o->frames,
                  "Number of frames (talk, tour; expressions has one per "
                  "expression and neutral)")
      ->capture_default_str();
  cmd->add_option("--program", o->program,
                  "talk (jaw, smile, brows), expressions (neutral then each at full weight) or "
                  "tour (each expression rises and falls in turn)")
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace gvkit::tools
