#include "gvkit/codec/sequence_info.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "gvkit/codec/gvid_format.hpp"

namespace gvkit::codec {

double SequenceInfo::step_mm() const {
  double extent = 0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, box_max_mm[a] - box_min_mm[a]);
  return extent / ((1 << bit_depth) - 1);
}

int64_t SequenceInfo::domain_pixels() const {
  return domain_mask.empty() ? 0 : cv::countNonZero(domain_mask);
}

double SequenceInfo::box_diagonal_mm() const { return cv::norm(box_max_mm - box_min_mm); }

Status SequenceInfo::check() const {
  if (width < 1 || height < 1 || width > format::kMaxDimension || height > format::kMaxDimension)
    return invalid_argument("size " + std::to_string(width) + "x" + std::to_string(height) +
                            " out of range (1.." + std::to_string(format::kMaxDimension) + ")");
  if (bit_depth < 8 || bit_depth > 16)
    return invalid_argument("bit depth " + std::to_string(bit_depth) + " out of range (8..16)");
  if (!std::isfinite(fps) || fps <= 0 || fps > 10000)
    return invalid_argument("fps " + std::to_string(fps) + " out of range");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(box_min_mm[a]) || !std::isfinite(box_max_mm[a]) ||
        box_max_mm[a] < box_min_mm[a] || std::abs(box_min_mm[a]) > 1e9 ||
        std::abs(box_max_mm[a]) > 1e9)
      return invalid_argument("quantization box invalid on axis " + std::to_string(a));
  if (!(step_mm() > 0)) return invalid_argument("quantization box is empty");
  if (domain_mask.type() != CV_8U || domain_mask.rows != height || domain_mask.cols != width)
    return invalid_argument("domain mask must be CV_8U and " + std::to_string(width) + "x" +
                            std::to_string(height));
  return Status::ok();
}

Result<SequenceInfo> make_sequence_info(const std::vector<GeometryImage>& frames, int bit_depth,
                                        double fps) {
  SequenceInfoBuilder builder(bit_depth, fps);
  for (const GeometryImage& f : frames) GVKIT_RETURN_IF_ERROR(builder.add(f));
  return builder.finish();
}

SequenceInfoBuilder::SequenceInfoBuilder(int bit_depth, double fps) {
  info_.bit_depth = bit_depth;
  info_.fps = fps;
}

Status SequenceInfoBuilder::add(const GeometryImage& f) {
  if (failed_) return failed_precondition("sequence info: a frame before this one failed");
  const std::string name = "frame " + std::to_string(frames_);
  const auto fail = [&](Status status) {
    failed_ = true;
    return status;
  };
  if (Status s = f.check(); !s.is_ok()) return fail(s.with_context(name));
  if (frames_ == 0) {
    info_.width = f.xyz_mm.cols;
    info_.height = f.xyz_mm.rows;
    info_.has_texture = !f.texture.empty();
    info_.domain_mask = f.domain_mask.clone();
  } else {
    if (f.xyz_mm.cols != info_.width || f.xyz_mm.rows != info_.height)
      return fail(invalid_argument(name + ": size differs from frame 0"));
    if (cv::countNonZero(f.domain_mask != info_.domain_mask) != 0)
      return fail(invalid_argument(name + ": domain mask differs from frame 0"));
    if (f.texture.empty() == info_.has_texture)
      return fail(invalid_argument(name + ": texture present in some frames only"));
  }
  int64_t count = 0;
  for (int y = 0; y < f.xyz_mm.rows; ++y) {
    const cv::Vec3f* p = f.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* m = f.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < f.xyz_mm.cols; ++x) {
      if (!m[x]) continue;
      ++count;
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], static_cast<double>(p[x][a]));
        hi_[a] = std::max(hi_[a], static_cast<double>(p[x][a]));
      }
    }
  }
  if (count == 0) return fail(invalid_argument(name + ": no domain pixel"));
  ++frames_;
  return Status::ok();
}

Result<SequenceInfo> SequenceInfoBuilder::finish() const {
  if (failed_) return failed_precondition("sequence info: a frame failed");
  if (frames_ == 0) return invalid_argument("no frames");
  SequenceInfo info = info_;
  info.domain_mask = info_.domain_mask.clone();
  cv::Vec3d lo = lo_, hi = hi_;
  // A flat box (a single point) still needs a positive step.
  for (int a = 0; a < 3; ++a)
    if (hi[a] - lo[a] < 1e-6) hi[a] = lo[a] + 1e-6;
  info.box_min_mm = lo;
  info.box_max_mm = hi;
  GVKIT_RETURN_IF_ERROR(info.check());
  return info;
}

Status check_frame_fits(const SequenceInfo& info, const GeometryImage& frame) {
  GVKIT_RETURN_IF_ERROR(frame.check());
  if (frame.xyz_mm.cols != info.width || frame.xyz_mm.rows != info.height)
    return invalid_argument("size differs from the sequence's");
  if (cv::countNonZero(frame.domain_mask != info.domain_mask) != 0)
    return invalid_argument("domain mask differs from the sequence's");
  if (frame.texture.empty() == info.has_texture)
    return invalid_argument(info.has_texture ? "texture missing" : "texture not in the sequence");
  for (int y = 0; y < frame.xyz_mm.rows; ++y) {
    const cv::Vec3f* p = frame.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* m = frame.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < frame.xyz_mm.cols; ++x)
      for (int a = 0; a < 3 && m[x]; ++a)
        if (!(p[x][a] >= info.box_min_mm[a] && p[x][a] <= info.box_max_mm[a]))
          return invalid_argument("pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                  ") outside the quantization box");
  }
  return Status::ok();
}

}  // namespace gvkit::codec
