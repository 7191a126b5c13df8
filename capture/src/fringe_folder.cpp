#include "gvkit/capture/fringe_folder.hpp"

#include <algorithm>
#include <cctype>

#include "gvkit/core/image_io.hpp"

namespace gvkit::capture {
namespace fs = std::filesystem;

Result<FringeFolder> list_fringe_folder(const fs::path& dir, int images_per_frame) {
  GVKIT_CHECK(images_per_frame > 0);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return not_found(dir.string() + ": no such folder");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png" || ext == ".bmp" || ext == ".tif" || ext == ".tiff" || ext == ".pgm")
      files.push_back(entry.path());
  }
  if (ec) return io_error(dir.string() + ": cannot list: " + ec.message());
  if (files.empty()) return not_found(dir.string() + ": no fringe images (.png, .bmp, .tif, .pgm)");
  if (files.size() % images_per_frame != 0)
    return invalid_argument(dir.string() + ": " + std::to_string(files.size()) +
                            " images is not a multiple of the pattern set's " +
                            std::to_string(images_per_frame) + " images per frame");
  std::sort(files.begin(), files.end());
  FringeFolder folder;
  folder.dir = dir;
  for (size_t i = 0; i < files.size(); i += images_per_frame)
    folder.frames.emplace_back(files.begin() + i, files.begin() + i + images_per_frame);
  return folder;
}

Result<FringeSet> read_fringe_frame(const FringeFolder& folder, size_t i) {
  GVKIT_CHECK(i < folder.frames.size());
  FringeSet set;
  set.index = static_cast<int64_t>(i);
  for (const fs::path& p : folder.frames[i]) {
    GVKIT_ASSIGN_OR_RETURN(cv::Mat image, read_image(p, true));
    set.images.push_back(image);
  }
  return set;
}

}  // namespace gvkit::capture
