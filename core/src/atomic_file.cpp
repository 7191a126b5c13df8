#include "gvkit/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

namespace gvkit {
namespace fs = std::filesystem;
namespace {

std::string errno_text() { return std::strerror(errno); }

fs::path temp_path_for(const fs::path& path) {
  return path.parent_path() / (path.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                               path.extension().string());
}

Status fsync_path(const fs::path& path, bool directory) {
  const int fd =
      ::open(path.empty() ? "." : path.c_str(), directory ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) return io_error(path.string() + ": cannot open for fsync: " + errno_text());
  const int rc = ::fsync(fd);
  const int saved = errno;
  ::close(fd);
  if (rc != 0 && !directory)
    return io_error(path.string() + ": fsync failed: " + std::strerror(saved));
  return Status::ok();
}

}  // namespace

Status write_via_temp_file(const fs::path& path,
                           const std::function<Status(const fs::path&)>& write) {
  const fs::path temp = temp_path_for(path);
  std::error_code ec;
  Status status = write(temp);
  if (status.is_ok()) status = fsync_path(temp, false);
  if (status.is_ok()) {
    fs::rename(temp, path, ec);
    if (ec) status = io_error(path.string() + ": cannot rename temporary file: " + ec.message());
  }
  if (!status.is_ok()) {
    fs::remove(temp, ec);
    return status;
  }
  static_cast<void>(fsync_path(path.parent_path(), true));  // best effort: entry durability
  return Status::ok();
}

Status write_file_atomically(const fs::path& path, std::string_view bytes) {
  return write_via_temp_file(path, [&](const fs::path& temp) -> Status {
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return io_error(path.string() + ": cannot create: " + errno_text());
    size_t written = 0;
    while (written < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
      if (n < 0) {
        if (errno == EINTR) continue;
        const std::string why = errno_text();
        ::close(fd);
        return io_error(path.string() + ": write failed: " + why);
      }
      written += static_cast<size_t>(n);
    }
    if (::close(fd) != 0) return io_error(path.string() + ": close failed: " + errno_text());
    return Status::ok();
  });
}

Result<std::string> read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  if (fs::is_directory(path, ec))
    return invalid_argument(path.string() + ": is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error(path.string() + ": cannot open: " + errno_text());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return io_error(path.string() + ": read failed");
  return buffer.str();
}

}  // namespace gvkit
