#include "gvkit/player/frame_sequence.hpp"

#include <system_error>

#include "gvkit/player/exr_folder_sequence.hpp"

namespace gvkit::player {
namespace fs = std::filesystem;

Result<std::unique_ptr<FrameSequence>> FrameSequence::create(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file or folder");
  if (fs::is_directory(path, ec)) {
    GVKIT_ASSIGN_OR_RETURN(auto seq, ExrFolderSequence::open(path));
    return std::unique_ptr<FrameSequence>(std::move(seq));
  }
  // INTEGRATION POINT (.gvid): when the codec lands, open "*.gvid" files here with
  // gvkit/codec/gvid_reader.hpp: a GvidSequence adapter whose frame_count/fps/frame/frame_bits
  // forward to GvidReader::frame_count, info().fps, decode_frame and frame_bits.
  return unsupported(path.string() +
                     ": not a folder of frame_NNNNNN.exr files (this build plays EXR folders)");
}

}  // namespace gvkit::player
