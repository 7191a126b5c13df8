# Every third-party dependency of gvkit, found once. scripts/setup installs them (Debian 12).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

# OpenCV: list components explicitly, else VTK and Qt come along.
set(GVKIT_OPENCV_COMPONENTS core imgproc imgcodecs calib3d video videoio features2d
    structured_light phase_unwrapping)
find_package(OpenCV 4 REQUIRED COMPONENTS ${GVKIT_OPENCV_COMPONENTS})
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenMesh REQUIRED)            # provides the OpenMeshCore target
find_package(OpenEXR REQUIRED)             # OpenEXR::OpenEXR
find_package(ZLIB REQUIRED)                # ZLIB::ZLIB (the codec's CRC-32)
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)  # EXR ZIP chunks (core)
find_package(TBB REQUIRED)                 # TBB::tbb
find_package(nlohmann_json 3 REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(CHOLMOD REQUIRED)             # cmake/FindCHOLMOD.cmake: CHOLMOD::CHOLMOD
find_package(dlib REQUIRED)                # dlib::dlib (face detector and 68-point landmarks)

if(GVKIT_WITH_V4L2)
  pkg_check_modules(LIBV4L2 REQUIRED IMPORTED_TARGET libv4l2 libv4lconvert)
endif()
if(GVKIT_WITH_LIBCAMERA)
  pkg_check_modules(LIBCAMERA REQUIRED IMPORTED_TARGET libcamera)
endif()
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavcodec libavformat libavutil libswscale)

if(GVKIT_WITH_PLAYER OR GVKIT_WITH_PROJECTOR)
  find_package(glfw3 3.3 REQUIRED)
  pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
endif()
if(GVKIT_WITH_PLAYER)
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
  pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
endif()

if(GVKIT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(GVKIT_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
