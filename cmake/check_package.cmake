# ctest: installs the build into a fresh prefix, then builds and runs the consumer
# program twice: through the CMake package (find_package(wavg), wavg::wavg) and through
# pkg-config (wavg.pc). The program runs on MESH when it exists.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK=... -DMESH=... -DCC=... -P check_package.cmake
# With -DTARBALL=wavg-X.Y.Z-linux-x86_64.tar.gz (`cargo xtask dist`'s) the prefix is that
# tarball unpacked instead of an install, and with -DVERSION=X.Y.Z and -DCXX=... a C program
# printing wavg_version() and a C++ one including wavg.hpp, both built with pkg-config's
# flags, must run and print VERSION.
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
if(TARBALL)
  file(MAKE_DIRECTORY ${WORK}/unpack)
  run(${CMAKE_COMMAND} -E chdir ${WORK}/unpack ${CMAKE_COMMAND} -E tar xzf ${TARBALL})
  file(GLOB top ${WORK}/unpack/*)
  file(RENAME ${top} ${prefix})
else()
  run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
endif()

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

if(VERSION)
  file(WRITE ${WORK}/version.c "#include <stdio.h>\n#include <wavg.h>\n\
int main(void) {\n  printf(\"%s %d.%d.%d\\n\", wavg_version(), WAVG_VERSION_MAJOR,\n\
         WAVG_VERSION_MINOR, WAVG_VERSION_PATCH);\n  return 0;\n}\n")
  file(WRITE ${WORK}/version.cpp "#include <cstdio>\n#include <wavg.hpp>\n\
int main() { std::printf(\"%s\\n\", wavg_version()); return 0; }\n")
  run(${CC} ${WORK}/version.c ${flags} -o ${WORK}/version_c)
  run(${CXX} -std=c++17 ${WORK}/version.cpp ${flags} -o ${WORK}/version_cpp)
  run(${WORK}/version_c)
  if(NOT out STREQUAL "${VERSION} ${VERSION}\n")
    message(FATAL_ERROR "version_c printed '${out}', not the library's and header's ${VERSION}")
  endif()
  run(${WORK}/version_cpp)
  if(NOT out STREQUAL "${VERSION}\n")
    message(FATAL_ERROR "version_cpp printed '${out}', not ${VERSION}")
  endif()
  message(STATUS "wavg_version() and the header: ${VERSION} (C and C++ consumers)")
endif()

# The installed library has no debug info; it is in libwavg.so.0.debug beside it (the
# tarball leaves that file out).
file(GLOB_RECURSE lib ${prefix}/*/libwavg.so.0)
if(TARBALL)
  file(SIZE ${lib} lib_size)
  message(STATUS "unpacked libwavg.so.0: ${lib_size} bytes")
else()
  if(NOT EXISTS "${lib}.debug")
    message(FATAL_ERROR "${lib}.debug (the separate debug info) was not installed")
  endif()
  file(SIZE ${lib} lib_size)
  file(SIZE ${lib}.debug debug_size)
  if(NOT lib_size LESS debug_size)
    message(FATAL_ERROR "${lib}: ${lib_size} bytes, debug info not stripped (${debug_size})")
  endif()
  message(STATUS "installed libwavg.so.0: ${lib_size} bytes (+ ${debug_size} bytes of debug info)")
endif()

if(EXISTS "${MESH}")
  foreach(exe ${WORK}/cmake/hello ${WORK}/hello_pc)
    run(${exe} ${MESH})
    message(STATUS "${exe}: ${out}")
  endforeach()
else()
  message(STATUS "built both consumers; SKIPPED running them: ${MESH} not found")
endif()
