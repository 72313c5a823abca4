# Installs the library as a CMake package: find_package(papertear) then
# target_link_libraries(app papertear::papertear). Headers keep their folder layout under
# include/papertear, so consumers write #include <core/simulation.hpp>.
include(CMakePackageConfigHelpers)
# The include directory comes from the target's INSTALL_INTERFACE (top-level CMakeLists.txt).
install(TARGETS papertear EXPORT papertearTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
foreach(dir core kernels fracture)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/papertear/${dir}
    FILES_MATCHING PATTERN "*.hpp")
endforeach()
install(EXPORT papertearTargets NAMESPACE papertear:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/papertearConfig.cmake.in
  ${PROJECT_BINARY_DIR}/papertearConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/papertearConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/papertearConfig.cmake ${PROJECT_BINARY_DIR}/papertearConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
