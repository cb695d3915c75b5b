# SPDX-License-Identifier: MIT
# ctest driver: install vkcloth from BUILD_DIR into a prefix, MOVE the prefix (the package must be
# relocatable), then configure, build and run the consumer against it; or, with MODE=subdir,
# build the consumer with add_subdirectory(SOURCE_DIR), unoptimised (see below).
# MODE=installed-minimal is `installed` with only the packages the public headers need:
# find_package(vkcloth) must not look for fmt, tinyobjloader, TinyGLTF, meshoptimizer (their
# libraries are linked by name) nor need VulkanHeaders' CMake package (the headers alone do).
set(work ${WORK_DIR}/${MODE})
file(REMOVE_RECURSE ${work})
file(MAKE_DIRECTORY ${work})
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
if(MODE MATCHES "^installed")
  set(minimal "")
  if(MODE STREQUAL "installed-minimal")
    foreach(package fmt tinyobjloader TinyGLTF meshoptimizer VulkanHeaders)
      list(APPEND minimal -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
    endforeach()
  endif()
  run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${work}/staged)
  file(RENAME ${work}/staged ${work}/moved)
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${work}/build -G Ninja -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_PREFIX_PATH=${work}/moved ${minimal})
else()
  # The whole engine compiles again inside the consumer: unoptimised (-O0, no debug info), since
  # this checks the CMake integration, not speed (cold on a 2-core VM: 78 s against 133 s for a
  # Release build, and nothing else runs beside this test). VKCLOTH_FMT_HEADER_ONLY=OFF (allowed: a
  # subproject installs nothing) links libfmt instead of compiling fmt's implementation into each of
  # the ~40 engine sources that format: 1.5 s less per source at -O0, ~25 % of this build. The
  # header-only default is what the release tree builds and the installed-package tests check.
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${work}/build -G Ninja -DCMAKE_BUILD_TYPE=Debug
      -DCMAKE_CXX_FLAGS_DEBUG=-O0 -DCMAKE_C_FLAGS_DEBUG=-O0 -DVKCLOTH_SOURCE_DIR=${SOURCE_DIR}
      -DVKCLOTH_FMT_HEADER_ONLY=OFF)
endif()
run(${CMAKE_COMMAND} --build ${work}/build)
run(${work}/build/consumer ${work})
