#pragma once
// A plain folder of fringe images (no session.json), e.g. the SLStudio skull frames or a folder a
// user's own rig wrote: the image files in natural order (img2 before img10), optionally filtered
// by name, taken `images_per_frame` at a time as consecutive frames, or as a sliding window over
// a continuous sequence (frame i = images i .. i + N - 1).

#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct FringeFolderOptions {
  // Shell globs on file names (fnmatch: *, ?, [abc]); empty = every image / none left out.
  std::string include;  // e.g. "cam0_*.png": only these
  std::string exclude;  // e.g. "*white*": never these
  // Continuous sequence: the projector cycles through the N patterns without pause and the
  // subject moves. Frame i is the window of images i .. i + N - 1, image j filling pattern slot
  // j mod N (every window holds each slot once). M images give M - N + 1 frames; each image is
  // shared by N frames. Without it, frames are disjoint groups of N.
  bool sliding = false;

  Status check() const;
};

struct FringeFolder {
  std::filesystem::path dir;
  std::vector<std::filesystem::path> images;               // every listed image, natural order
  std::vector<std::vector<std::filesystem::path>> frames;  // per frame, images in slot order
  // Per frame, the position in `images` of its first image (its capture time for --sliding).
  std::vector<size_t> first_image;
};

// Natural order of names: digit runs compare as numbers ("img2" < "img10"), the rest bytewise.
bool natural_less(const std::string& a, const std::string& b);

// Lists the .png/.bmp/.tif/.tiff/.pgm/.ppm/.jpg files of dir that pass the options' globs, in
// natural order. Fails naming the folder when it is missing or no image passes.
Result<std::vector<std::filesystem::path>> list_fringe_images(const std::filesystem::path& dir,
                                                              const FringeFolderOptions& options);

// Lists the images and groups them into frames. Fails naming the folder when it is missing, has
// no images, holds fewer than images_per_frame, or (without sliding) a count that is not a
// multiple of images_per_frame; that message gives the first and last file, and when the names
// follow several patterns (a stray white.png beside img_01.png ...), each pattern's count.
Result<FringeFolder> list_fringe_folder(const std::filesystem::path& dir, int images_per_frame,
                                        const FringeFolderOptions& options = {});

// Reads frame i as grey images (colour is converted). Fails naming the file when it cannot be
// read, or when its size or bit depth differs from the frame's first image (naming both).
Result<FringeSet> read_fringe_frame(const FringeFolder& folder, size_t i);

// The name patterns of a list of files: each name with its digit runs replaced by '#', with the
// number of files per pattern, most common first ("img_#.png (12)").
std::vector<std::pair<std::string, int>> file_name_patterns(
    const std::vector<std::filesystem::path>& files);

}  // namespace gvkit::capture
