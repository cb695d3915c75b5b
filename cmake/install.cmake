# SPDX-License-Identifier: MIT
# `cmake --install` produces a relocatable package: headers, the library (static by default,
# shared with -DBUILD_SHARED_LIBS=ON), and a CMake config for find_package(vkcloth CONFIG).
# Shaders are embedded in the library; the public headers need glm and Vulkan-Headers only.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS vkcloth EXPORT vkclothTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/vkcloth DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
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
