#pragma once
// The seed's HM baseline (section 5.4): a harmonic map of the face, with the eyes and mouth
// filled, to the W x H rectangle with an arc-length boundary map and no feature constraint. The
// rim's arc length starts where the line from the nose tip (30) through the chin (8) meets the
// rim (frontal x-y plane), which goes to the middle of the bottom edge; the map is mirrored if
// needed so the subject's right eye is on the image's left, as in the canonical domain.

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_boundaries.hpp"
#include "gvkit/facemap/mapped_face.hpp"

namespace gvkit::facemap {

struct HarmonicMapOptions {
  FaceBoundaryOptions boundaries;
  bool measure_quality = true;
  Status check() const { return boundaries.check(); }
};

// Maps mesh onto a size.width x size.height geometry image whose mask covers every pixel. Fails
// like find_face_boundaries.
Result<MappedFace> map_face_hm(const Mesh& mesh, const FaceLandmarks& landmarks, cv::Size size,
                               const HarmonicMapOptions& options = {});

}  // namespace gvkit::facemap
