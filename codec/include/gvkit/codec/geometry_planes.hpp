#pragma once
// GeometryImage <-> coded sample planes. Positions are quantized in the sequence's box with one
// step for all axes (SequenceInfo::step_mm); pixels outside the domain are filled smoothly
// (push-pull: masked averages down a pyramid, bilinear back up) so they cost few bits; planes
// are padded to whole 16x16 macroblocks by repeating the last row and column.

#include <vector>

#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

// Planes X, Y, Z (B bits) and, if info.has_texture, T (8 bits), each padded to multiples of 16.
// Preconditions (contract): image size equals info's, image.check() passes. Rounds with AVX2
// where the processor has it: the same samples as quantize_geometry_reference.
std::vector<SamplePlane> quantize_geometry(const GeometryImage& image, const SequenceInfo& info);
// The plain version of quantize_geometry.
std::vector<SamplePlane> quantize_geometry_reference(const GeometryImage& image,
                                                     const SequenceInfo& info);

// The inverse: xyz_mm = box_min + q * step (outside the domain too: smooth filler values),
// texture = q / 255, the header's domain mask; index and timestamp from frame_number and fps.
GeometryImage dequantize_geometry(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                                  int64_t frame_number);
// The same into `image`, whose xyz_mm and texture buffers are written over where they already
// have the right size and type (Mat::create): a caller that owns them alone (a decoder reusing
// the buffers of a frame its user has let go) so saves their allocation and first touch.
void dequantize_geometry_into(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                              int64_t frame_number, GeometryImage& image);
// The plain version of dequantize_geometry (which uses AVX2 where the processor has it and
// returns the same values bit for bit).
GeometryImage dequantize_geometry_reference(const std::vector<SamplePlane>& planes,
                                            const SequenceInfo& info, int64_t frame_number);

// width x height values (row-major) as a plane: rounded (halves away from zero), clamped to
// [0, max_value], padded to multiples of 16 by repeating the last row and column.
SamplePlane to_plane(const std::vector<double>& values, int width, int height, int max_value);

// Replaces values where mask == 0 by a smooth fill from the values where mask != 0 (width x
// height, row-major). With no masked-in value, every value becomes 0.
void fill_outside_domain(std::vector<double>& values, int width, int height, const cv::Mat& mask);

}  // namespace gvkit::codec
