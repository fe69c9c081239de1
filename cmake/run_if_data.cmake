# ctest helper: runs COMMAND (a list) when MESH exists, else prints SKIPPED (the test's
# SKIP_REGULAR_EXPRESSION then reports it as skipped).
#   cmake -DMESH=... -DCOMMAND=prog;arg;... -P run_if_data.cmake
if(NOT EXISTS "${MESH}")
  message(STATUS "SKIPPED: ${MESH} not found (set WAVG_DATA_DIR)")
  return()
endif()
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${COMMAND} failed: ${rc}")
endif()
