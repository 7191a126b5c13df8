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
if(GVKIT_BUILD_FUZZERS)
  # Every library is instrumented for coverage and checked by ASan + UBSan; the fuzzer
  # executables add -fsanitize=fuzzer at link time (tests/fuzz/CMakeLists.txt).
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "GVKIT_BUILD_FUZZERS needs clang (CC=clang CXX=clang++)")
  endif()
  set(_gvkit_fuzz -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                  -fno-sanitize-recover=undefined)
  add_compile_options(${_gvkit_fuzz})
  add_link_options(-fsanitize=address,undefined)
endif()
