#include "gvkit/core/gl_driver_modules.hpp"

#include <dlfcn.h>
#include <link.h>

#include <string>

namespace gvkit {

void pin_gl_driver_modules() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        const std::string name = info->dlpi_name ? info->dlpi_name : "";
        if (name.find("_dri.so") != std::string::npos ||
            name.find("gallium") != std::string::npos || name.find("GLX_mesa") != std::string::npos)
          (void)dlopen(name.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}

}  // namespace gvkit
