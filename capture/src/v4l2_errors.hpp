#pragma once
// errno from a V4L2 call -> a Status naming the device and what went wrong.

#include <cerrno>
#include <cstring>
#include <string>

#include "gvkit/core/status.hpp"

namespace gvkit::detail {

inline Status v4l2_errno_status(const std::string& device, const std::string& what, int error) {
  const std::string prefix = device + ": " + what + ": ";
  switch (error) {
    case ENOENT:
    case ENXIO:
      return not_found(prefix + "no such device");
    case EACCES:
    case EPERM:
      return io_error(prefix +
                      "permission denied (is the user in the 'video' group, or is the device "
                      "node readable?)");
    case EBUSY:
      return io_error(prefix + "device busy (another program is streaming from it)");
    case ENODEV:
      return io_error(prefix + "the device vanished (unplugged or its driver unloaded)");
    case ENOTTY:
      return unsupported(prefix + "not a V4L2 device or the driver lacks this ioctl");
    default:
      return io_error(prefix + std::strerror(error));
  }
}

}  // namespace gvkit::detail
