# ctest: installs the build into a fresh prefix, then builds and runs the consumer
# program twice: through the CMake package (find_package(wavg), wavg::wavg) and through
# pkg-config (wavg.pc). The program runs on MESH when it exists.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK=... -DMESH=... -DCC=... -P check_package.cmake
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# CMake package.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/ffi_tests/consumer -B ${WORK}/cmake
    -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK}/cmake)

# pkg-config.
file(GLOB_RECURSE pc ${prefix}/*/wavg.pc)
get_filename_component(pcdir "${pc}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pcdir})
run(pkg-config --cflags --libs wavg)
separate_arguments(flags UNIX_COMMAND "${out}")
string(REGEX MATCH "-L([^ ]+)" _ "${out}")
run(${CC} ${SOURCE_DIR}/ffi_tests/consumer/hello.c ${flags} -Wl,-rpath,${CMAKE_MATCH_1}
    -o ${WORK}/hello_pc)

if(EXISTS "${MESH}")
  foreach(exe ${WORK}/cmake/hello ${WORK}/hello_pc)
    run(${exe} ${MESH})
    message(STATUS "${exe}: ${out}")
  endforeach()
else()
  message(STATUS "built both consumers; SKIPPED running them: ${MESH} not found")
endif()
