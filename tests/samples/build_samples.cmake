# Installs the built gvkit into a scratch prefix, configures and builds samples/ against it with
# find_package(gvkit), and runs a sample on the shared data when it is present.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${GVKIT_BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${GVKIT_SOURCE_DIR}/samples -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_CXX_FLAGS=${EXTRA_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${EXTRA_FLAGS}")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j2)
if(EXISTS ${SHARED_DATA}/slstudio-skull-2x3/calibration.xml)
  run(${WORK_DIR}/build/calibration_summary ${SHARED_DATA}/slstudio-skull-2x3/calibration.xml)
else()
  message(STATUS "shared data absent: built the samples, ran none")
endif()
