# Installs the built gvkit into a scratch prefix, configures and builds samples/ against it with
# find_package(gvkit), and runs the samples (all but the player window, which needs a display).
file(REMOVE_RECURSE ${WORK_DIR})
# run(<expected output regex> <command...>): fails unless the command exits 0 and prints a match.
function(run expect)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "${expect}")
    message(FATAL_ERROR "output of ${ARGN} does not match '${expect}':\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run("" ${CMAKE_COMMAND} --install ${GVKIT_BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run("" ${CMAKE_COMMAND} -S ${GVKIT_SOURCE_DIR}/samples -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_CXX_FLAGS=${EXTRA_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${EXTRA_FLAGS}")
run("" ${CMAKE_COMMAND} --build ${WORK_DIR}/build -j2)
set(bin ${WORK_DIR}/build)
set(gvkit ${GVKIT_BUILD_DIR}/tools/gvkit)

# decode_stats on a stored stream; its frames back to EXRs (gvkit decode) and encode_folder
# makes a stream of them again, which decode_stats reads.
set(golden ${GVKIT_SOURCE_DIR}/tests/golden/v2/intra_slow_qpm6_64.gvid)
run("frames 64x64.*\n +0 +I " ${bin}/decode_stats ${golden})
run("" ${gvkit} decode ${golden} -o ${WORK_DIR}/gv)
run("frames 64x64 -> .*again.gvid, [0-9]+ bytes" ${bin}/encode_folder ${WORK_DIR}/gv
    ${WORK_DIR}/again.gvid 20)
run(" +1 +P " ${bin}/decode_stats ${WORK_DIR}/again.gvid)
if(EXISTS ${bin}/mini_player)
  run("frames at .*\nfirst frame 64x64" ${bin}/mini_player ${WORK_DIR}/again.gvid --check)
endif()

if(EXISTS ${SHARED_DATA}/slstudio-skull-2x3/calibration.xml)
  run("baseline" ${bin}/calibration_summary ${SHARED_DATA}/slstudio-skull-2x3/calibration.xml)
  run("" ${gvkit} synth -o ${WORK_DIR}/session --frames 1 --size 128x96 --no-progress
      --ict ${SHARED_DATA}/ict-facekit)
  run("frame 0 .*128x96, valid share 0\\.[0-9]+, depth [0-9.]+ \\.\\. [0-9.]+ mm"
      ${bin}/reconstruct_fringes ${WORK_DIR}/session 0 ${WORK_DIR}/scan.exr)
else()
  message(STATUS "shared data absent: calibration_summary and reconstruct_fringes not run")
endif()
