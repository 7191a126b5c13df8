#include "gvkit/capture/fringe_folder.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cctype>
#include <map>

#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/image_io.hpp"

namespace gvkit::capture {
namespace fs = std::filesystem;
namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_image_extension(const std::string& extension) {
  const std::string ext = ascii_lower(extension);
  for (const char* known : {".png", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".jpg", ".jpeg"})
    if (ext == known) return true;
  return false;
}

bool glob_matches(const std::string& glob, const std::string& name) {
  return fnmatch(glob.c_str(), name.c_str(), 0) == 0;
}

std::string describe(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows) + " " +
         (image.depth() == CV_16U ? "16-bit" : "8-bit");
}

}  // namespace

Status FringeFolderOptions::check() const {
  for (const std::string* glob : {&include, &exclude})
    if (glob->find('/') != std::string::npos)
      return invalid_argument("image name glob '" + *glob +
                              "' must match file names, not paths (no '/')");
  return Status::ok();
}

bool natural_less(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      size_t i_end = i, j_end = j;
      while (i_end < a.size() && is_digit(a[i_end])) ++i_end;
      while (j_end < b.size() && is_digit(b[j_end])) ++j_end;
      // Compare the numbers without their leading zeros: longer is larger, else digit by digit.
      size_t i_first = i, j_first = j;
      while (i_first + 1 < i_end && a[i_first] == '0') ++i_first;
      while (j_first + 1 < j_end && b[j_first] == '0') ++j_first;
      const size_t i_len = i_end - i_first, j_len = j_end - j_first;
      if (i_len != j_len) return i_len < j_len;
      const int c = a.compare(i_first, i_len, b, j_first, j_len);
      if (c != 0) return c < 0;
      // Equal numbers: fewer leading zeros first, so the order is total.
      if (i_end - i != j_end - j) return i_end - i < j_end - j;
      i = i_end;
      j = j_end;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i;
    ++j;
  }
  return a.size() - i < b.size() - j;
}

std::vector<std::pair<std::string, int>> file_name_patterns(const std::vector<fs::path>& files) {
  std::map<std::string, int> counts;
  for (const fs::path& f : files) {
    std::string pattern;
    for (char c : f.filename().string())
      if (!is_digit(c))
        pattern += c;
      else if (pattern.empty() || pattern.back() != '#')
        pattern += '#';
    ++counts[pattern];
  }
  std::vector<std::pair<std::string, int>> out(counts.begin(), counts.end());
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& x, const auto& y) { return x.second > y.second; });
  return out;
}

Result<std::vector<fs::path>> list_fringe_images(const fs::path& dir,
                                                 const FringeFolderOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return not_found(dir.string() + ": no such folder");
  std::vector<fs::path> files;
  int filtered = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file() || !is_image_extension(entry.path().extension().string()))
      continue;
    const std::string name = entry.path().filename().string();
    if ((!options.include.empty() && !glob_matches(options.include, name)) ||
        (!options.exclude.empty() && glob_matches(options.exclude, name))) {
      ++filtered;
      continue;
    }
    files.push_back(entry.path());
  }
  if (ec) return io_error(dir.string() + ": cannot list: " + ec.message());
  if (files.empty()) {
    if (filtered > 0)
      return not_found(dir.string() + ": none of its " + std::to_string(filtered) +
                       " images passes the name filter (include '" + options.include +
                       "', exclude '" + options.exclude + "')");
    return not_found(dir.string() + ": no fringe images (.png, .bmp, .tif, .pgm, .ppm, .jpg)");
  }
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return files;
}

Result<FringeFolder> list_fringe_folder(const fs::path& dir, int images_per_frame,
                                        const FringeFolderOptions& options) {
  GVKIT_CHECK(images_per_frame > 0);
  GVKIT_ASSIGN_OR_RETURN(std::vector<fs::path> files, list_fringe_images(dir, options));
  const size_t n = static_cast<size_t>(images_per_frame);
  const bool fits = options.sliding ? files.size() >= n : files.size() % n == 0;
  if (!fits) {
    std::string message =
        dir.string() + ": " + std::to_string(files.size()) + " images (" +
        files.front().filename().string() + " .. " + files.back().filename().string() + ") " +
        (options.sliding ? "are fewer than" : "is not a multiple of") + " the pattern set's " +
        std::to_string(images_per_frame) + " images per frame";
    const auto patterns = file_name_patterns(files);
    if (patterns.size() > 1) {
      message += "; the names follow " + std::to_string(patterns.size()) + " patterns:";
      for (const auto& [pattern, count] : patterns)
        message += " " + pattern + " (" + std::to_string(count) + ")";
      message += "; keep one with --images GLOB or leave some out with --exclude GLOB";
    } else {
      message += "; check --pattern, or whether images are missing";
    }
    return invalid_argument(message);
  }
  FringeFolder folder;
  folder.dir = dir;
  folder.images = files;
  if (options.sliding) {
    for (size_t i = 0; i + n <= files.size(); ++i) {
      std::vector<fs::path> frame(n);
      for (size_t j = i; j < i + n; ++j) frame[j % n] = files[j];
      folder.frames.push_back(std::move(frame));
      folder.first_image.push_back(i);
    }
  } else {
    for (size_t i = 0; i < files.size(); i += n) {
      folder.frames.emplace_back(files.begin() + i, files.begin() + i + n);
      folder.first_image.push_back(i);
    }
  }
  return folder;
}

Result<FringeSet> read_fringe_frame(const FringeFolder& folder, size_t i) {
  GVKIT_CHECK(i < folder.frames.size());
  FringeSet set;
  set.index = static_cast<int64_t>(i);
  for (const fs::path& p : folder.frames[i]) {
    GVKIT_ASSIGN_OR_RETURN(cv::Mat image, read_image(p, true));
    if (!set.images.empty()) {
      const cv::Mat& first = set.images.front();
      if (image.size() != first.size() || image.depth() != first.depth())
        return invalid_argument(p.string() + ": " + describe(image) + ", but " +
                                folder.frames[i].front().string() + " (frame " + std::to_string(i) +
                                "'s first image) is " + describe(first));
    }
    set.images.push_back(image);
  }
  return set;
}

}  // namespace gvkit::capture
