# Warnings and sanitizers shared by every gvkit target (an interface library, not global flags).
add_library(gvkit_compile_options INTERFACE)
target_compile_options(gvkit_compile_options INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wno-unused-parameter>)
if(GVKIT_SANITIZE)
  set(_gvkit_san -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_compile_options(${_gvkit_san})
  add_link_options(${_gvkit_san})
endif()
install(TARGETS gvkit_compile_options EXPORT gvkitTargets)
