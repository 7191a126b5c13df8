#pragma once

namespace gvkit {

// Marks the OpenGL driver modules loaded in this process (Mesa's *_dri.so, libgallium,
// libGLX_mesa) RTLD_NODELETE, so they stay mapped until the process exits. Call it after a GL
// context has been made current (the driver is loaded then). glfwTerminate would otherwise unload
// the driver, and LeakSanitizer would report the driver's own process-lifetime allocations from
// an "<unknown module>"; pinned, they stay reachable from the driver's globals. Harmless without
// sanitizers: the driver lives as long as the process anyway. Never fails.
void pin_gl_driver_modules();

}  // namespace gvkit
