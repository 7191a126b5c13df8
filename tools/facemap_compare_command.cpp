// gvkit facemap compare GV_A GV_B: the mapping metrics of two `facemap map` outputs side by side.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "command.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::tools {
namespace {

std::string cell(const nlohmann::json& summary, const std::string& key, int index = -1) {
  if (!summary.contains(key)) return "-";
  const nlohmann::json& v = index >= 0 ? summary[key][index] : summary[key];
  char buf[64];
  if (v.is_number_integer())
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v.get<int64_t>()));
  else if (v.is_number())
    std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
  else
    return v.dump();
  return buf;
}

void run(const std::string& a, const std::string& b) {
  const auto ja = value_or_throw(read_json(std::filesystem::path(a) / "stats.json"));
  const auto jb = value_or_throw(read_json(std::filesystem::path(b) / "stats.json"));
  for (const auto* j : {&ja, &jb})
    if (!j->contains("summary") || !j->contains("options"))
      throw CommandFailed(corrupt_data("stats.json without summary/options"));
  const auto& sa = ja["summary"];
  const auto& sb = jb["summary"];
  std::printf("%-34s %16s %16s\n", "metric", ja["options"].value("method", "?").c_str(),
              jb["options"].value("method", "?").c_str());
  auto row = [&](const char* label, const std::string& key, int index = -1) {
    std::printf("%-34s %16s %16s\n", label, cell(sa, key, index).c_str(),
                cell(sb, key, index).c_str());
  };
  row("frames mapped", "mapped");
  row("frames failed", "failed");
  row("flipped triangles (total)", "flipped_total");
  row("eps_angle (mean)", "eps_angle_mean");
  row("eps_area (mean)", "eps_area_mean");
  row("key feature drift px (mean)", "key_feature_drift_px_mean");
  row("key feature drift px (max)", "key_feature_drift_px_max");
  row("all-landmark drift px (mean)", "feature_drift_px_mean");
  row("temporal MSE X mm^2", "temporal_mse_mm2", 0);
  row("temporal MSE Y mm^2", "temporal_mse_mm2", 1);
  row("temporal MSE Z mm^2", "temporal_mse_mm2", 2);
  row("temporal MSE mean mm^2", "temporal_mse_mean_mm2");
  row("temporal MSE per area mm^2", "temporal_mse_area_weighted_mm2");
  row("true surface drift mm (RMS)", "true_drift_rms_mm");
  row("temporal MSE without drift mm^2", "temporal_mse_drift_free_mean_mm2");
  row("  the same per area mm^2", "temporal_mse_drift_free_area_weighted_mm2");
  row("map time s/frame", "map_time_s_mean");
  if (sa.contains("temporal_mse_mean_mm2") && sb.contains("temporal_mse_mean_mm2") &&
      sb["temporal_mse_mean_mm2"].get<double>() > 0)
    std::printf(
        "%-34s %16.3f\n", "temporal MSE ratio A/B",
        sa["temporal_mse_mean_mm2"].get<double>() / sb["temporal_mse_mean_mm2"].get<double>());
}

}  // namespace

void add_facemap_compare_command(CLI::App& app) {
  auto* cmd = facemap_group(app)->add_subcommand(
      "compare", "Print the mapping metrics of two `facemap map` outputs side by side");
  auto a = std::make_shared<std::string>(), b = std::make_shared<std::string>();
  cmd->add_option("gv_a", *a, "First output folder (with stats.json)")->required();
  cmd->add_option("gv_b", *b, "Second output folder (with stats.json)")->required();
  cmd->callback([a, b] { run(*a, *b); });
}

}  // namespace gvkit::tools
