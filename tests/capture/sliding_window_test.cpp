// A continuous N-step sequence over a moving subject, read as sliding windows: the projector
// cycles through the 4 patterns without pause while the bump slides sideways, and every window
// of 4 consecutive images is one frame (image j in pattern slot j mod 4). Each window must
// reconstruct the surface as it was in the middle of the window, within a bound that grows with
// the motion: the phase-shift motion artefact (the pixel sees a different surface point in each
// image, so the fitted phase ripples at twice the fringe frequency).
#include <gtest/gtest.h>

#include <cstdio>

#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "plain_folder_fixture.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {
namespace fs = std::filesystem;

struct Motion {
  double worst_rms_mm = 0, mean_rms_mm = 0, worst_valid_share = 1;
  int windows = 0;
};

// Renders `images` images of a bump moving speed_mm per image along x, image j under pattern
// j mod N, writes them as a folder, reads them back as sliding windows and compares each window
// with the truth at its middle instant.
Motion slide(const std::string& pattern, double speed_mm, int images) {
  testing::TempDir dir;
  const Calibration calibration = fixture::rig({160, 128});
  auto set = create_pattern_set(pattern);
  EXPECT_TRUE(set);
  const int n = (*set)->image_count();
  const std::vector<cv::Mat> patterns = (*set)->generate({912, 570});
  const SyntheticRenderer renderer(calibration, {});
  std::vector<cv::Mat> sequence;
  for (int j = 0; j < images; ++j) {
    const SyntheticScene scene = fixture::bump_scene(-20 + speed_mm * j);
    sequence.push_back(renderer.render(scene, {patterns[j % n]}, 11 + j).images[0]);
  }
  fixture::write_numbered(dir.path(), sequence, "seq", "png", 0);

  FringeFolderOptions options;
  options.sliding = true;
  auto folder = list_fringe_folder(dir.path(), n, options);
  EXPECT_TRUE(folder) << folder.status().message();
  EXPECT_EQ(folder->frames.size(), static_cast<size_t>(images - n + 1));
  ReconstructOptions reconstruct_options;
  reconstruct_options.depth_prior_mm = 780;  // most of the view is the wall
  auto reconstructor = Reconstructor::create(calibration, reconstruct_options);
  EXPECT_TRUE(reconstructor);
  Motion m;
  for (size_t i = 0; i < folder->frames.size(); ++i) {
    auto fringes = read_fringe_frame(*folder, i);
    EXPECT_TRUE(fringes) << fringes.status().message();
    auto scan = reconstructor->reconstruct(*fringes, **set);
    EXPECT_TRUE(scan) << scan.status().message();
    const double middle = static_cast<double>(folder->first_image[i]) + 0.5 * (n - 1);
    const SyntheticFrame truth =
        renderer.render(fixture::bump_scene(-20 + speed_mm * middle), {}, 0);
    const fixture::DepthError e = fixture::depth_error(*scan, truth.truth);
    m.worst_rms_mm = std::max(m.worst_rms_mm, e.rms_mm);
    m.mean_rms_mm += e.rms_mm / folder->frames.size();
    m.worst_valid_share = std::min(m.worst_valid_share, e.valid_share);
    ++m.windows;
  }
  std::printf("%s, %.2f mm per image: %d windows, RMS mean %.3f worst %.3f mm, valid >= %.4f\n",
              pattern.c_str(), speed_mm, m.windows, m.mean_rms_mm, m.worst_rms_mm,
              m.worst_valid_share);
  return m;
}

TEST(SlidingWindow, EveryWindowOfAMovingSubjectReconstructs) {
  const Motion still = slide("psp4-f16", 0.0, 7);
  const Motion slow = slide("psp4-f16", 0.5, 9);
  const Motion fast = slide("psp4-f16", 2.0, 9);
  EXPECT_EQ(slow.windows, 6);
  // A still subject: as good as disjoint frames.
  EXPECT_LT(still.worst_rms_mm, 0.25);
  // Moving: bounded, and worse with speed (the motion artefact).
  EXPECT_LT(slow.worst_rms_mm, 0.3);
  EXPECT_LT(fast.worst_rms_mm, 1.0);
  EXPECT_GT(fast.mean_rms_mm, slow.mean_rms_mm);
  EXPECT_GT(slow.mean_rms_mm, still.mean_rms_mm);
  for (const Motion* m : {&still, &slow, &fast}) EXPECT_GT(m->worst_valid_share, 0.95);
}

TEST(SlidingWindow, TemporalSetsSlideToo) {
  // A multi-frequency set cycled continuously: each window still holds every slot once.
  const Motion m = slide("mf3-f16-f1", 0.5, 8);
  EXPECT_EQ(m.windows, 3);
  EXPECT_LT(m.worst_rms_mm, 0.7);
  EXPECT_GT(m.worst_valid_share, 0.95);
}

}  // namespace
}  // namespace gvkit::capture
