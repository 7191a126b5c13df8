// libcamera_source.hpp for builds without libcamera (GVKIT_WITH_LIBCAMERA=OFF).
#include "gvkit/capture/libcamera_source.hpp"

namespace gvkit {

Result<std::vector<LibcameraCameraInfo>> list_libcamera_cameras() {
  return unsupported("libcamera: this gvkit was built without libcamera (GVKIT_WITH_LIBCAMERA)");
}

Result<std::unique_ptr<FrameSource>> open_libcamera_source(const std::string& id,
                                                           const FrameSourceOptions& options) {
  return unsupported("libcamera:" + id +
                     ": this gvkit was built without libcamera (GVKIT_WITH_LIBCAMERA)");
}

}  // namespace gvkit
