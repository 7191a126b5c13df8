# Install the libraries, headers and a CMake package so that another project can say
# find_package(gvkit) and link gvkit::core, gvkit::capture, ... (samples/ is built that way).
include(CMakePackageConfigHelpers)
set(GVKIT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/gvkit)
install(EXPORT gvkitTargets NAMESPACE gvkit:: DESTINATION ${GVKIT_CMAKE_DIR})
configure_package_config_file(cmake/gvkitConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/gvkitConfig.cmake INSTALL_DESTINATION ${GVKIT_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/gvkitConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${CMAKE_CURRENT_BINARY_DIR}/gvkitConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/gvkitConfigVersion.cmake
  cmake/GvkitDependencies.cmake
  cmake/FindCHOLMOD.cmake
  DESTINATION ${GVKIT_CMAKE_DIR})
