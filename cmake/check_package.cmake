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
# No -Wl,-rpath here and no LD_LIBRARY_PATH below: the .pc file's flags must suffice.
run(${CC} ${SOURCE_DIR}/ffi_tests/consumer/hello.c ${flags} -o ${WORK}/hello_pc)
unset(ENV{LD_LIBRARY_PATH})

# The installed library has no debug info; it is in libwavg.so.0.debug beside it.
file(GLOB_RECURSE lib ${prefix}/*/libwavg.so.0)
if(NOT EXISTS "${lib}.debug")
  message(FATAL_ERROR "${lib}.debug (the separate debug info) was not installed")
endif()
file(SIZE ${lib} lib_size)
file(SIZE ${lib}.debug debug_size)
if(NOT lib_size LESS debug_size)
  message(FATAL_ERROR "${lib}: ${lib_size} bytes, debug info not stripped (${debug_size})")
endif()
message(STATUS "installed libwavg.so.0: ${lib_size} bytes (+ ${debug_size} bytes of debug info)")

if(EXISTS "${MESH}")
  foreach(exe ${WORK}/cmake/hello ${WORK}/hello_pc)
    run(${exe} ${MESH})
    message(STATUS "${exe}: ${out}")
  endforeach()
else()
  message(STATUS "built both consumers; SKIPPED running them: ${MESH} not found")
endif()
