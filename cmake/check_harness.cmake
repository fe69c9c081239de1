# ctest pass criteria of the OpenMesh harness on one mesh (SKIPPED when it is missing):
# the output is one valid JSON object with every required key, the least-squares mesh
# matches the independent Eigen solve (lsmesh_max_rel_diff <= 1e-8), both decimations
# reach the target, and ours has no more flipped triangles than OpenMesh's. The
# distance and time comparisons are printed, not judged.
#   cmake -DHARNESS=... -DMESH=... -P check_harness.cmake
cmake_minimum_required(VERSION 3.19) # string(JSON)
if(NOT EXISTS "${MESH}")
  message(STATUS "SKIPPED: ${MESH} not found (set WAVG_DATA_DIR)")
  return()
endif()
execute_process(COMMAND ${HARNESS} ${MESH} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                OUTPUT_STRIP_TRAILING_WHITESPACE)
message(STATUS "${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "harness failed: ${rc}")
endif()
set(required mesh vertices target_vertices ours_hausdorff openmesh_hausdorff ours_mean_dist
    openmesh_mean_dist ours_seconds openmesh_seconds ours_flipped openmesh_flipped
    lsmesh_max_rel_diff ours_vertices openmesh_vertices)
foreach(key ${required})
  string(JSON ${key} ERROR_VARIABLE err GET "${out}" ${key})
  if(err)
    message(FATAL_ERROR "not a JSON object with key ${key}: ${err}")
  endif()
endforeach()
if(NOT lsmesh_max_rel_diff LESS_EQUAL 1e-8)
  message(FATAL_ERROR "lsmesh_max_rel_diff = ${lsmesh_max_rel_diff} > 1e-8")
endif()
if(NOT ours_vertices EQUAL target_vertices)
  message(FATAL_ERROR "our decimation has ${ours_vertices} vertices, not ${target_vertices}")
endif()
if(ours_flipped GREATER openmesh_flipped)
  message(FATAL_ERROR "ours_flipped = ${ours_flipped} > openmesh_flipped = ${openmesh_flipped}")
endif()
foreach(v ours_hausdorff ours_mean_dist)
  if(NOT ${v} GREATER_EQUAL 0)
    message(FATAL_ERROR "${v} = ${${v}} is not a distance")
  endif()
endforeach()
