# cmake -DPROGRAM=mesh_footprint -DMESH=file.obj -DEXPECT=regex -P run_on_mesh.cmake
# Runs the example on a mesh that may be absent (shared data): prints "SKIPPED:" then (a CTest
# SKIP_REGULAR_EXPRESSION), fails on a non-zero exit code or output not matching EXPECT.
if(NOT EXISTS "${MESH}")
  message("SKIPPED: ${MESH} not found")
  return()
endif()
execute_process(COMMAND "${PROGRAM}" "${MESH}" RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT code EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} ${MESH} exited with ${code}")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "output of ${PROGRAM} ${MESH} does not match '${EXPECT}'")
endif()
