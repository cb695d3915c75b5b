# SPDX-License-Identifier: MIT
# `cmake --install` produces a relocatable package: headers, the library (static by default,
# shared with -DBUILD_SHARED_LIBS=ON), and a CMake config for find_package(vkcloth CONFIG).
# Shaders are embedded in the library. What find_package(vkcloth) asks of a consumer is what the
# public headers need: glm (CMake package) and the Vulkan headers (VulkanHeaders' CMake package, or
# the headers alone). Nothing else: fmt is compiled into the library (header-only, privately),
# nlohmann_json is header-only and private, stb is internal to the library (no stbi_* symbols),
# volk is renamed vkcloth_*. A static libvkcloth still needs its private libraries at the
# consumer's link (tinyobjloader_double, tinygltf, meshoptimizer, Threads, dl): the config names
# them through vkcloth::private_link, as CMake targets when their packages are there, else as
# plain library names for the linker (-ltinygltf...). A shared libvkcloth needs none of them.
# GLM's version at configure time is installed as vkcloth/glm_version.hpp (vkcloth/glm_abi.hpp).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The umbrella vkcloth::vkcloth and its four layers (engine/CMakeLists.txt); the kernel headers and
# the testing header (engine/testing) stay in the source tree.
set(vkcloth_libraries vkcloth_core vkcloth_io vkcloth_gpu vkcloth_render)
install(TARGETS vkcloth ${vkcloth_libraries} EXPORT vkclothTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/vkcloth DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The generated public header (engine/CMakeLists.txt): the GLM version the library was built with.
get_target_property(vkcloth_binary_dir vkcloth_core BINARY_DIR)
install(FILES ${vkcloth_binary_dir}/include/vkcloth/glm_version.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vkcloth)

# The static library's private libraries, for the config: each as "package|target|library name".
# The library name is the file name of the library the build used (libtinygltf.so -> tinygltf).
set(VKCLOTH_PRIVATE_LINK "")
get_target_property(vkcloth_type vkcloth_core TYPE)
if(vkcloth_type STREQUAL "STATIC_LIBRARY")
  foreach(dep IN ITEMS "tinyobjloader|tinyobjloader::tinyobjloader_double" "TinyGLTF|TinyGLTF::TinyGLTF"
                       "meshoptimizer|meshoptimizer::meshoptimizer")
    string(REPLACE "|" ";" parts "${dep}")
    list(GET parts 1 dep_target)
    get_target_property(dep_location ${dep_target} LOCATION)
    get_filename_component(dep_name "${dep_location}" NAME)
    if(NOT dep_name MATCHES "^(lib)?([A-Za-z0-9_+-]+)\\.")
      message(FATAL_ERROR "vkcloth install: no library name in ${dep_target}'s location '${dep_location}'")
    endif()
    list(APPEND VKCLOTH_PRIVATE_LINK "${dep}|${CMAKE_MATCH_2}")
  endforeach()
  target_link_libraries(vkcloth INTERFACE $<INSTALL_INTERFACE:vkcloth::private_link>)
endif()

install(EXPORT vkclothTargets NAMESPACE vkcloth:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vkcloth)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vkclothConfig.cmake.in
  ${PROJECT_BINARY_DIR}/vkclothConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vkcloth)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/vkclothConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/vkclothConfig.cmake ${PROJECT_BINARY_DIR}/vkclothConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vkcloth)
if(TARGET vkcloth_cli)
  install(TARGETS vkcloth_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
