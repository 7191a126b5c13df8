#include "support/test_support.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <random>

namespace gvkit::testing {
namespace fs = std::filesystem;

TempDir::TempDir() {
  std::random_device rd;
  path_ = fs::temp_directory_path() /
          ("gvkit-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

fs::path shared_data_dir() {
  const char* env = std::getenv("GVKIT_SHARED_DATA");
  fs::path dir = env ? fs::path(env) : fs::path(GVKIT_SHARED_DATA_DIR);
  std::error_code ec;
  return fs::is_directory(dir, ec) ? dir : fs::path();
}

CommandResult run_gvkit(const std::string& arguments) {
  const char* env = std::getenv("GVKIT_BINARY");
  const char* binary = env ? env : GVKIT_BINARY_PATH;
  CommandResult result;
  const std::string command = std::string(binary) + " " + arguments + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

}  // namespace gvkit::testing
