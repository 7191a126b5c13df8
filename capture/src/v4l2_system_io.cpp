// The real V4L2 system calls: libv4l2 when available and wanted (it hides some driver quirks),
// else the plain calls.
#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#ifdef GVKIT_HAVE_LIBV4L2
#include <libv4l2.h>
#endif

#include "gvkit/capture/v4l2_io.hpp"

namespace gvkit {
namespace {

class PlainV4l2Io : public V4l2Io {
 public:
  int open(const std::string& path, int flags) override { return ::open(path.c_str(), flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override { return ::ioctl(fd, request, arg); }
  void* mmap(size_t length, int prot, int flags, int fd, int64_t offset) override {
    return ::mmap(nullptr, length, prot, flags, fd, offset);
  }
  int munmap(void* address, size_t length) override { return ::munmap(address, length); }
  int poll(int fd, int timeout_ms) override {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms);
  }
};

#ifdef GVKIT_HAVE_LIBV4L2
class Libv4l2Io final : public PlainV4l2Io {
 public:
  int open(const std::string& path, int flags) override { return v4l2_open(path.c_str(), flags); }
  int close(int fd) override { return v4l2_close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    return v4l2_ioctl(fd, request, arg);
  }
  void* mmap(size_t length, int prot, int flags, int fd, int64_t offset) override {
    return v4l2_mmap(nullptr, length, prot, flags, fd, offset);
  }
  int munmap(void* address, size_t length) override { return v4l2_munmap(address, length); }
};
#endif

}  // namespace

std::shared_ptr<V4l2Io> make_system_v4l2_io(bool use_libv4l2) {
#ifdef GVKIT_HAVE_LIBV4L2
  if (use_libv4l2) return std::make_shared<Libv4l2Io>();
#endif
  return std::make_shared<PlainV4l2Io>();
}

}  // namespace gvkit
