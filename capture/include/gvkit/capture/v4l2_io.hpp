#pragma once
// V4l2Io: the thin seam between the V4L2 backend and the system calls it makes, so a fake driver
// can stand in for a device in tests. Each call behaves as the system call of the same name:
// it returns -1 (or MAP_FAILED for mmap) and sets errno on failure.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace gvkit {

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int open(const std::string& path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* mmap(size_t length, int prot, int flags, int fd, int64_t offset) = 0;
  virtual int munmap(void* address, size_t length) = 0;
  // Waits up to timeout_ms for a frame (POLLIN): > 0 ready, 0 timed out, -1 with errno.
  virtual int poll(int fd, int timeout_ms) = 0;
};

// The real devices: through libv4l2 (v4l2_open, v4l2_ioctl, v4l2_mmap, ...) when gvkit is built
// with it and use_libv4l2 is true, else the plain system calls (no emulated formats, no libv4l2
// messages on stderr: what a device listing wants).
std::shared_ptr<V4l2Io> make_system_v4l2_io(bool use_libv4l2 = true);

}  // namespace gvkit
