// Reconstructs one fringe set of a session folder (`gvkit synth` or `gvkit record` writes them)
// into a range scan: prints the share of valid pixels and the depth range, and writes the scan
// as an EXR when asked.
//   reconstruct_fringes SESSION [FRAME [OUT.exr]]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <gvkit/capture/pattern_set.hpp>
#include <gvkit/capture/reconstructor.hpp>
#include <gvkit/capture/session_reader.hpp>
#include <gvkit/core/exr_io.hpp>

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::fprintf(stderr, "usage: %s SESSION [FRAME [OUT.exr]]\n", argv[0]);
    return 2;
  }
  auto fail = [](const gvkit::Status& s) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return 1;
  };
  auto session = gvkit::capture::SessionReader::open(argv[1]);
  if (!session.is_ok()) return fail(session.status());
  const long frame = argc > 2 ? std::atol(argv[2]) : 0;
  if (frame < 0 || static_cast<size_t>(frame) >= session->frame_count())
    return fail(gvkit::invalid_argument("frame " + std::to_string(frame) + " is not in 0.." +
                                        std::to_string(session->frame_count() - 1)));
  auto patterns = gvkit::capture::create_pattern_set(session->info().pattern);
  if (!patterns.is_ok()) return fail(patterns.status());
  auto reconstructor = gvkit::capture::Reconstructor::create(session->calibration());
  if (!reconstructor.is_ok()) return fail(reconstructor.status());
  auto fringes = session->read_frame(static_cast<size_t>(frame));
  if (!fringes.is_ok()) return fail(fringes.status());
  auto scan = reconstructor->reconstruct(*fringes, **patterns);
  if (!scan.is_ok()) return fail(scan.status());
  double z_min = INFINITY, z_max = -INFINITY;
  for (int y = 0; y < scan->xyz_mm.rows; ++y)
    for (int x = 0; x < scan->xyz_mm.cols; ++x) {
      const double z = scan->xyz_mm.at<cv::Vec3f>(y, x)[2];
      if (std::isfinite(z)) z_min = std::min(z_min, z), z_max = std::max(z_max, z);
    }
  std::printf("frame %ld (%s, %zu images): %dx%d, valid share %.3f, depth %.1f .. %.1f mm\n", frame,
              (*patterns)->name().c_str(), fringes->images.size(), scan->xyz_mm.cols,
              scan->xyz_mm.rows, scan->valid_fraction(), z_min, z_max);
  if (argc > 3)
    if (gvkit::Status s = gvkit::write_range_scan_exr(argv[3], *scan); !s.is_ok()) return fail(s);
  return 0;
}
