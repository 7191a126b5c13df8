// gvkit synth -o SESSION: renders a synthetic structured-light session of the ICT face (the
// embedded default source) with ground truth.
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <regex>
#include <string>

#include "command.hpp"
#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/synthetic_session.hpp"

namespace gvkit::tools {
namespace {

std::filesystem::path default_ict_dir() {
  if (const char* env = std::getenv("GVKIT_SHARED_DATA"))
    return std::filesystem::path(env) / "ict-facekit";
  return GVKIT_DEFAULT_SHARED_DATA "/ict-facekit";
}

}  // namespace

void add_synth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "synth", "Render a synthetic fringe session of the ICT face with ground truth (gt/)");
  auto options = std::make_shared<capture::SyntheticSessionOptions>();
  auto output = std::make_shared<std::string>();
  auto size = std::make_shared<std::string>("512x512");
  auto ict = std::make_shared<std::string>(default_ict_dir().string());
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("-o,--output", *output, "Session folder to create")->required();
  cmd->add_option("--frames", options->frames, "Number of frames")->capture_default_str();
  cmd->add_option("--size", *size, "Camera image size WxH (30 degree HFOV kept)")
      ->capture_default_str();
  cmd->add_option("--pattern", options->pattern, "Pattern set: " + capture::pattern_set_help())
      ->capture_default_str();
  std::string tracks;
  for (const auto& n : capture::expression_track_names())
    tracks += (tracks.empty() ? "" : ", ") + n;
  cmd->add_option("--expressions", options->expressions, "Expression track: " + tracks)
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "Seed of expressions and noise")->capture_default_str();
  cmd->add_flag("--head-motion", options->head_motion, "Add slow head rotation and translation");
  cmd->add_option("--fps", options->fps, "Frames per second (timestamps)")->capture_default_str();
  cmd->add_option("--distance", options->face_distance_mm, "Face distance from the camera (mm)")
      ->capture_default_str();
  cmd->add_option("--noise", options->render.noise_sigma,
                  "Camera noise sigma as a fraction of the intensity range (0.01 = 1 %)")
      ->capture_default_str();
  cmd->add_option("--gamma", options->render.projector_gamma, "Projector gamma (response v^gamma)")
      ->capture_default_str();
  cmd->add_option("--gamma-compensate", options->gamma_compensation,
                  "Send patterns through a v^(1/G) LUT (0 = off)")
      ->capture_default_str();
  cmd->add_option("--bit-depth", options->render.bit_depth, "Camera bit depth: 8, 10, 12, 16")
      ->capture_default_str();
  cmd->add_option("--camera-blur", options->render.camera_blur_px, "Camera defocus sigma (px)")
      ->capture_default_str();
  cmd->add_option("--projector-blur", options->render.projector_blur_px,
                  "Projector defocus sigma (projector px)")
      ->capture_default_str();
  cmd->add_option("--ambient", options->render.ambient, "Ambient light relative to the projector")
      ->capture_default_str();
  cmd->add_option("--ict", *ict, "ICT-FaceKit folder")->capture_default_str();
  auto projector = std::make_shared<std::string>();
  cmd->add_option("--projector-size", *projector,
                  "Projector WxH (default 912x570); its focal length scales with the width, so "
                  "the field of view stays");
  cmd->add_flag("--plain-folder", options->plain_folder,
                "Write a plain folder (img_1.png, img_2.png, ... + calibration.yml + gt/) instead "
                "of a session: another rig's data as gvkit meets it");
  cmd->add_option("--image-format", options->image_format, "Plain folder: png or bmp")
      ->capture_default_str();
  auto layout = std::make_shared<std::string>("procam");
  cmd->add_option("--calibration-layout", *layout,
                  "Plain folder: calibration.yml layout: gvkit, slstudio, procam or stereo")
      ->capture_default_str();
  cmd->add_flag("--no-progress", *quiet, "Do not show progress");
  cmd->callback([options, output, size, ict, quiet, projector, layout] {
    std::smatch m;
    if (!std::regex_match(*size, m, std::regex(R"((\d+)x(\d+))")))
      throw CommandFailed(
          invalid_argument("--size must be WxH, e.g. 512x512, not '" + *size + "'"));
    options->rig.camera_width = std::stoi(m[1]);
    options->rig.camera_height = std::stoi(m[2]);
    if (!projector->empty()) {
      if (!std::regex_match(*projector, m, std::regex(R"((\d+)x(\d+))")))
        throw CommandFailed(invalid_argument("--projector-size must be WxH, e.g. 1280x800, not '" +
                                             *projector + "'"));
      const int width = std::stoi(m[1]);
      options->rig.projector_focal_px *= static_cast<double>(width) / options->rig.projector_width;
      options->rig.projector_width = width;
      options->rig.projector_height = std::stoi(m[2]);
    }
    const std::map<std::string, CalibrationFormat> layouts = {
        {"gvkit", CalibrationFormat::kGvkit},
        {"slstudio", CalibrationFormat::kSlStudio},
        {"procam", CalibrationFormat::kProcam},
        {"stereo", CalibrationFormat::kStereo}};
    if (!layouts.count(*layout))
      throw CommandFailed(
          invalid_argument("--calibration-layout must be gvkit, slstudio, procam "
                           "or stereo, not '" +
                           *layout + "'"));
    options->calibration_layout = layouts.at(*layout);
    options->ict_dir = *ict;
    options->progress = !*quiet;
    throw_if_error(capture::write_synthetic_session(*output, *options));
    std::printf("wrote %d frames to %s\n", options->frames, output->c_str());
  });
}

}  // namespace gvkit::tools
