#pragma once
// A plain folder of fringe images (no session.json), e.g. the SLStudio skull frames: the image
// files sorted by name, taken `images_per_frame` at a time as consecutive frames.

#include <filesystem>
#include <vector>

#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct FringeFolder {
  std::filesystem::path dir;
  std::vector<std::vector<std::filesystem::path>> frames;
};

// Lists .png/.bmp/.tif/.tiff/.pgm files. Fails naming the folder when it is missing, has no
// images, or their count is not a multiple of images_per_frame.
Result<FringeFolder> list_fringe_folder(const std::filesystem::path& dir, int images_per_frame);
// Reads frame i as grey images. Fails naming the file.
Result<FringeSet> read_fringe_frame(const FringeFolder& folder, size_t i);

}  // namespace gvkit::capture
