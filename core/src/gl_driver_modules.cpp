#include "gvkit/core/gl_driver_modules.hpp"

#include <dlfcn.h>
#include <link.h>

#include <string>
#include <vector>

namespace gvkit {

void pin_gl_driver_modules() {
  // The names first, the dlopen calls after: dl_iterate_phdr holds the loader's lock on its list
  // of objects while its callback runs, and a dlopen from the callback waits for the loader's
  // main lock, which a dlopen on another thread (OpenCV's codecs, opencv_media.hpp) holds while
  // it waits for the first: a deadlock.
  std::vector<std::string> names;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* data) {
        const std::string name = info->dlpi_name ? info->dlpi_name : "";
        if (name.find("_dri.so") != std::string::npos ||
            name.find("gallium") != std::string::npos || name.find("GLX_mesa") != std::string::npos)
          static_cast<std::vector<std::string>*>(data)->push_back(name);
        return 0;
      },
      &names);
  for (const std::string& name : names)
    (void)dlopen(name.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
}

}  // namespace gvkit
