#include "gvkit/player/frame_sequence.hpp"

#include <system_error>

#include "gvkit/player/exr_folder_sequence.hpp"
#include "gvkit/player/gvid_sequence.hpp"

namespace gvkit::player {
namespace fs = std::filesystem;

Result<std::unique_ptr<FrameSequence>> FrameSequence::create(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file or folder");
  if (fs::is_directory(path, ec)) {
    GVKIT_ASSIGN_OR_RETURN(auto seq, ExrFolderSequence::open(path));
    return std::unique_ptr<FrameSequence>(std::move(seq));
  }
  if (path.extension() == ".gvid") {
    GVKIT_ASSIGN_OR_RETURN(auto seq, GvidSequence::open(path));
    return std::unique_ptr<FrameSequence>(std::move(seq));
  }
  return unsupported(path.string() + ": not a .gvid stream nor a folder of frame_NNNNNN.exr files");
}

}  // namespace gvkit::player
