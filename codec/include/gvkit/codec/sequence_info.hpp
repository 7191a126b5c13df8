#pragma once
// What a .gvid stream's header says about the whole sequence: picture size, sample bit depth,
// frame rate, planes, the quantization box and the domain mask.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

struct SequenceInfo {
  int width = 0, height = 0;  // pixels, 1..16384 each
  int bit_depth = 16;         // B: X, Y, Z samples are B-bit (8..16); texture is always 8-bit
  double fps = 30.0;
  bool has_texture = false;                            // a fourth plane with the 8-bit texture
  cv::Vec3d box_min_mm{0, 0, 0}, box_max_mm{1, 1, 1};  // quantization box
  cv::Mat domain_mask;  // CV_8U, height x width, 255 inside the domain, 0 outside

  // One quantization step for all three axes (mm): the box's largest extent / (2^B - 1), so
  // x, y and z are treated alike. Sample q of axis a decodes to box_min_mm[a] + q * step_mm().
  double step_mm() const;
  int64_t domain_pixels() const;
  // Length of the box diagonal (mm): the peak of the geometry PSNR.
  double box_diagonal_mm() const;
  // Ok when sizes, bit depth, fps, box and mask are consistent and in range.
  Status check() const;
};

// The SequenceInfo of a video: size and mask of the first frame (every frame must match), and
// the bounding box of all domain pixels of all frames. Fails naming the first frame that differs
// in size or mask, or when a frame has no domain pixel.
Result<SequenceInfo> make_sequence_info(const std::vector<GeometryImage>& frames, int bit_depth,
                                        double fps);

// make_sequence_info over frames given one at a time, in frame order, so that a long video need
// not be held in memory: add() checks each frame as make_sequence_info does (the same messages,
// "frame N: ..."), finish() gives the same SequenceInfo.
class SequenceInfoBuilder {
 public:
  SequenceInfoBuilder(int bit_depth, double fps);
  // The next frame (frame 0 first). After a failure the builder takes no more frames.
  Status add(const GeometryImage& frame);
  // Fails without frames or after a failed add().
  Result<SequenceInfo> finish() const;
  int64_t frames() const { return frames_; }

 private:
  SequenceInfo info_;
  cv::Vec3d lo_{1e300, 1e300, 1e300}, hi_{-1e300, -1e300, -1e300};
  int64_t frames_ = 0;
  bool failed_ = false;
};

// Whether `frame` fits `info`: the same size, domain mask and texture presence, and every domain
// pixel inside the quantization box. Fails saying which does not (no frame name; the caller adds
// it). Checks a frame read again after the box was made (a file changed in between).
Status check_frame_fits(const SequenceInfo& info, const GeometryImage& frame);

}  // namespace gvkit::codec
