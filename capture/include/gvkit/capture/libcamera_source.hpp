#pragma once
// The libcamera frame source ("libcamera:<id>", or "libcamera:<n>" for the n-th camera, or
// "libcamera:" for the first): a CameraManager, one camera, a queue of buffer_count requests
// cycling through one mono / raw / YUV stream whose luma is delivered. Exposure
// (controls::ExposureTime, auto exposure off) and frame duration (controls::FrameDurationLimits
// from fps) are set on every request. libcamera's API is used in libcamera_source.cpp only.

#include <memory>
#include <string>
#include <vector>

#include "gvkit/capture/frame_source.hpp"

namespace gvkit {

struct LibcameraCameraInfo {
  std::string id;
  std::string model;                 // controls/properties Model, when the pipeline reports it
  std::vector<std::string> formats;  // "R8 640x480", one line per pixel format with its sizes
};

// The cameras libcamera sees. An empty list (no cameras) is not an error; failing to start the
// camera manager is. Unsupported when gvkit was built without libcamera.
Result<std::vector<LibcameraCameraInfo>> list_libcamera_cameras();

// Fails naming the id: no cameras at all ("libcamera sees no cameras"), unknown id (listing the
// ones there are), camera busy, no stream configuration gvkit reads.
Result<std::unique_ptr<FrameSource>> open_libcamera_source(const std::string& id,
                                                           const FrameSourceOptions& options);

}  // namespace gvkit
