#pragma once
// FrameSequence over a folder of frame_NNNNNN.exr files: GeometryImages, or RangeScans shown as
// geometry images. fps comes from a stats.json or session.json "fps" field in the folder when
// there is one, else 30. frame_bits is the size of each EXR file.

#include <filesystem>
#include <memory>
#include <vector>

#include "gvkit/core/frame_files.hpp"
#include "gvkit/player/frame_sequence.hpp"

namespace gvkit::player {

class ExrFolderSequence : public FrameSequence {
 public:
  enum class Kind { kGeometryImage, kRangeScan };

  // Lists the folder and reads the first frame's channel names to decide the kind. Fails naming
  // the folder when it is missing, empty, or the first frame is unreadable.
  static Result<std::unique_ptr<ExrFolderSequence>> open(const std::filesystem::path& dir);

  std::string name() const override;
  int64_t frame_count() const override { return static_cast<int64_t>(files_.size()); }
  double fps() const override { return fps_; }
  Result<GeometryImage> frame(int64_t index) override;
  std::optional<int64_t> frame_bits(int64_t index) const override;
  Kind kind() const { return kind_; }

 private:
  ExrFolderSequence() = default;
  std::filesystem::path dir_;
  std::vector<FrameFile> files_;
  std::vector<int64_t> file_bits_;
  double fps_ = 30.0;
  Kind kind_ = Kind::kGeometryImage;
};

}  // namespace gvkit::player
