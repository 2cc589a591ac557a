# cmake -P: `cmake --install` of the build tree into a fresh prefix, then what a user of the
# installed package does: find_package(Quiver) from a C and a C++ program (shared, then static),
# pkg-config from a plain compiler command, the tools from the prefix's bin.
# -DBUILD=<build tree> -DSOURCE=<source tree> -DBINARY=<scratch> -DMODEL=<a .qvr> -DQUIVER_VERSION=<x.y.z>
cmake_policy(VERSION 3.20)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    string(JOIN " " line ${ARGN})
    message(FATAL_ERROR "failed (${status}): ${line}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${BINARY})
set(prefix ${BINARY}/prefix)
string(REGEX MATCH "^[0-9]+\\.[0-9]+" soversion ${QUIVER_VERSION})
run(${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix})
foreach(file bin/quiver bin/quiver-mesh bin/quiver-bake bin/quiver-view include/quiver/quiver.h
    include/quiver/quiver_config.h lib/libquiver_runtime.a lib/libquiver_runtime.so lib/libquiver_runtime.so.${soversion}
    lib/cmake/Quiver/QuiverConfig.cmake lib/cmake/Quiver/QuiverConfigVersion.cmake lib/cmake/Quiver/QuiverTargets.cmake
    lib/pkgconfig/quiver.pc)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "cmake --install did not install ${file}")
  endif()
endforeach()
run(${prefix}/bin/quiver info ${MODEL})
if(EXISTS ${BUILD}/python/quiver)  # the Python module, where Debian's python3 looks under a prefix
  run(${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/lib/python3/dist-packages
    /usr/bin/python3 -c "print(__import__('quiver').Model('${MODEL}').info.r)")  # no ';': a CMake list
  string(STRIP "${out}" r)
  if(NOT r STREQUAL "10")
    message(FATAL_ERROR "the installed Python module read r = '${r}'")
  endif()
endif()

# The CMake package, shared and static, from a C-only project and from a C and C++ one.
foreach(variant shared static)
  foreach(languages c c-cpp)
    set(build ${BINARY}/consumer-${variant}-${languages})
    set(use_static OFF)
    if(variant STREQUAL "static")
      set(use_static ON)
    endif()
    set(c_only OFF)
    if(languages STREQUAL "c")
      set(c_only ON)
    endif()
    run(${CMAKE_COMMAND} -S ${SOURCE}/tests/install/consumer -B ${build} -G Ninja -DCMAKE_PREFIX_PATH=${prefix}
      -DQuiver_USE_STATIC_RUNTIME=${use_static} -DC_ONLY=${c_only} -DQUIVER_EXAMPLE=${SOURCE}/examples/embed/main.c)
    run(${CMAKE_COMMAND} --build ${build})
    run(${build}/consumer_c ${MODEL} 60)
    if(NOT out MATCHES "after 60 frames")
      message(FATAL_ERROR "the C consumer (${variant}, ${languages}) printed: ${out}")
    endif()
    if(NOT c_only)
      run(${build}/consumer_cpp ${MODEL})
      if(NOT out MATCHES "from C\\+\\+: r = ")
        message(FATAL_ERROR "the C++ consumer (${variant}) printed: ${out}")
      endif()
    endif()
    run(readelf -d ${build}/consumer_c)
    if(variant STREQUAL "shared" AND NOT out MATCHES "libquiver_runtime\\.so\\.${soversion}")
      message(FATAL_ERROR "the shared consumer does not load libquiver_runtime.so.${soversion}:\n${out}")
    elseif(variant STREQUAL "static" AND out MATCHES "libquiver_runtime")
      message(FATAL_ERROR "the static consumer loads the shared runtime:\n${out}")
    endif()
    message(STATUS "find_package(Quiver), ${variant} runtime, ${languages} project: its programs ran")
  endforeach()
endforeach()

# Another minor version is not compatible (0.x): a project asking for the previous one fails.
string(REGEX MATCHALL "[0-9]+" parts ${QUIVER_VERSION})
list(GET parts 0 major)
list(GET parts 1 minor)
math(EXPR previous "${minor} - 1")
if(previous GREATER_EQUAL 0)
file(WRITE ${BINARY}/old/CMakeLists.txt
  "cmake_minimum_required(VERSION 3.18)\nproject(old LANGUAGES C)\nfind_package(Quiver ${major}.${previous} REQUIRED)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${BINARY}/old -B ${BINARY}/old/build -DCMAKE_PREFIX_PATH=${prefix}
  RESULT_VARIABLE status OUTPUT_QUIET ERROR_QUIET)
if(status EQUAL 0)
  message(FATAL_ERROR "find_package(Quiver ${major}.${previous}) accepted version ${QUIVER_VERSION}")
endif()
endif()

# pkg-config, from a plain compiler command line.
set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
run(pkg-config --modversion quiver)
string(STRIP "${out}" version)
if(NOT version STREQUAL QUIVER_VERSION)
  message(FATAL_ERROR "pkg-config says version '${version}', the project ${QUIVER_VERSION}")
endif()
run(pkg-config --cflags --libs quiver)
separate_arguments(flags UNIX_COMMAND "${out}")
run(cc -std=c99 -Wall -Wextra -Werror ${SOURCE}/examples/embed/main.c ${flags} -o ${BINARY}/pkgconfig_consumer)
set(ENV{LD_LIBRARY_PATH} ${prefix}/lib)
run(${BINARY}/pkgconfig_consumer ${MODEL} 60)
if(NOT out MATCHES "after 60 frames")
  message(FATAL_ERROR "the pkg-config consumer printed: ${out}")
endif()
message(STATUS "pkg-config: the C consumer built with `cc $(pkg-config --cflags --libs quiver)` ran")
