#include "gvkit/facemap/eip_map.hpp"

#include <gtest/gtest.h>

#include <queue>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/facemap/block_matching.hpp"
#include "gvkit/facemap/canonical_domain.hpp"
#include "gvkit/facemap/harmonic_map_baseline.hpp"
#include "gvkit/facemap/map_metrics.hpp"
#include "support/test_support.hpp"

namespace gvkit::facemap {
namespace {

// Test-only distance: Dijkstra along edges.
Result<std::vector<double>> dijkstra(const Mesh& mesh,
                                     const std::vector<Mesh::VertexHandle>& sources) {
  std::vector<double> d(mesh.n_vertices(), INFINITY);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  for (auto source : sources) {
    d[source.idx()] = 0;
    q.emplace(0, source.idx());
  }
  while (!q.empty()) {
    auto [dv, v] = q.top();
    q.pop();
    if (dv > d[v]) continue;
    for (auto w : mesh.vv_range(Mesh::VertexHandle(v))) {
      const double nd = dv + (mesh.point(w) - mesh.point(Mesh::VertexHandle(v))).norm();
      if (nd < d[w.idx()]) d[w.idx()] = nd, q.emplace(nd, w.idx());
    }
  }
  return d;
}

FaceLandmarks ict_landmarks(const IctFaceModel& model, const std::vector<cv::Vec3d>& pos) {
  FaceLandmarks lm;
  for (int v : model.landmark_vertices())
    lm.points_mm.emplace_back(pos[v][0], pos[v][1], pos[v][2]);
  return lm;
}

TEST(EipMap, IctExpressions) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen", "mouthSmile_L", "mouthSmile_R",
                                                         "eyeBlink_L", "browInnerUp_L"});
  ASSERT_TRUE(model.is_ok());
  auto spec = CanonicalDomainSpec::from_ict(*model);
  ASSERT_TRUE(spec.is_ok()) << spec.status().message();
  const int n = std::getenv("FM2N") ? std::atoi(std::getenv("FM2N")) : 64;
  auto domain = CanonicalDomain::create(*spec, {n, n});
  ASSERT_TRUE(domain.is_ok()) << domain.status().message();
  std::printf("domain extrema %d nonmono %d flipped %d\n",
              domain->flow().field_report.interior_extrema, domain->flow().boundary_nonmonotone,
              domain->flow().flipped);
  std::vector<std::map<std::string, double>> exprs = {
      {},
      {{"jawOpen", 0.3}},
      {{"jawOpen", 0.7}},
      {{"mouthSmile_L", 0.8}, {"mouthSmile_R", 0.8}},
      {{"eyeBlink_L", 0.6}},
      {{"browInnerUp_L", 1.0}},
      {{"browInnerUp_L", 0.001}}};
  std::vector<MappedFace> eip, hm;
  std::vector<std::vector<cv::Vec3d>> positions;
  for (const auto& e : exprs) {
    auto pos = model->evaluate(e);
    const Mesh mesh = model->face_mesh(pos);
    auto mapped =
        map_face_eip(mesh, ict_landmarks(*model, pos), *domain,
                     std::getenv("FM2DIJ") ? DistanceFunction(dijkstra) : heat_geodesic_distance());
    ASSERT_TRUE(mapped.is_ok()) << mapped.status().message();
    auto h = map_face_hm(mesh, ict_landmarks(*model, pos), {n, n});
    ASSERT_TRUE(h.is_ok()) << h.status().message();
    std::printf(
        "EIP stflip %d cornerflip %d/%d extrema %d nonmono %d angle %.3f area %.3f | HM flip %d "
        "angle %.3f area %.3f\n",
        mapped->st_flipped, mapped->quality.flipped, mapped->quality.triangles,
        mapped->interior_extrema, mapped->boundary_nonmonotone, mapped->quality.eps_angle,
        mapped->quality.eps_area, h->quality.flipped, h->quality.eps_angle, h->quality.eps_area);
    eip.push_back(std::move(*mapped));
    hm.push_back(std::move(*h));
    positions.push_back(pos);
  }
  for (size_t i = 1; i < exprs.size(); ++i) {
    auto fd = feature_drift(eip[0].landmarks_px, eip[i].landmarks_px, {36, 39, 42, 45, 60, 62, 64});
    auto fa = feature_drift(eip[0].landmarks_px, eip[i].landmarks_px,
                            {17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32, 33,
                             34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50,
                             51, 52, 53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 65, 66, 67});
    auto hd = feature_drift(hm[0].landmarks_px, hm[i].landmarks_px, {36, 39, 42, 45, 60, 62, 64});
    auto td = true_surface_drift(eip[0], eip[i], positions[i]);
    auto htd = true_surface_drift(hm[0], hm[i], positions[i]);
    auto bm = block_matching_error(eip[0].image, eip[i].image);
    auto hbm = block_matching_error(hm[0].image, hm[i].image);
    std::printf("HM lm8 %.2f %.2f -> %.2f %.2f; lm36 %.2f %.2f -> %.2f %.2f\n",
                hm[0].landmarks_px[8].x(), hm[0].landmarks_px[8].y(), hm[i].landmarks_px[8].x(),
                hm[i].landmarks_px[8].y(), hm[0].landmarks_px[36].x(), hm[0].landmarks_px[36].y(),
                hm[i].landmarks_px[36].x(), hm[i].landmarks_px[36].y());
    std::printf("EIP lm62 %.2f %.2f -> %.2f %.2f; lm42 %.2f %.2f -> %.2f %.2f\n",
                eip[0].landmarks_px[62].x(), eip[0].landmarks_px[62].y(),
                eip[i].landmarks_px[62].x(), eip[i].landmarks_px[62].y(),
                eip[0].landmarks_px[42].x(), eip[0].landmarks_px[42].y(),
                eip[i].landmarks_px[42].x(), eip[i].landmarks_px[42].y());
    std::printf(
        "expr %zu: EIP key drift mean %.3f max %.3f all-lm mean %.3f | true rms %.3f max %.3f | bm "
        "%.4f (zero %.4f) || HM key drift mean %.3f max %.3f true rms %.3f bm %.4f (zero %.4f)\n",
        i, fd.mean, fd.max, fa.mean, td.rms, td.max, bm->mean_mse_mm2, bm->zero_motion_mean_mse_mm2,
        hd.mean, hd.max, htd.rms, hbm->mean_mse_mm2, hbm->zero_motion_mean_mse_mm2);
  }
}

}  // namespace
}  // namespace gvkit::facemap
