# Installs the library as a CMake package: find_package(papertear) then
# target_link_libraries(app papertear::papertear) (and papertear::io, papertear::render). Headers keep their folder layout under
# include/papertear, so consumers write #include <core/simulation.hpp>.
include(CMakePackageConfigHelpers)
# The include directory comes from the target's INSTALL_INTERFACE (top-level CMakeLists.txt).
install(TARGETS papertear EXPORT papertearTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
foreach(dir core kernels fracture)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/papertear/${dir}
    FILES_MATCHING PATTERN "*.hpp")
endforeach()
# The CLI's scene/summary code and its renderer, for hosts that want scene files, --set
# overrides, summary.json and the surface mesh / glb without rewriting them:
# papertear::io (tools/*.hpp) and papertear::render (tools/render/*.hpp).
set(PAPERTEAR_PACKAGE_HAS_TOOLS OFF)
if(TARGET papertear_io AND TARGET papertear_render)
  set(PAPERTEAR_PACKAGE_HAS_TOOLS ON)
  set_target_properties(papertear_io PROPERTIES EXPORT_NAME io)
  set_target_properties(papertear_render PROPERTIES EXPORT_NAME render)
  install(TARGETS papertear_io papertear_render EXPORT papertearTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/papertear/tools
    FILES_MATCHING PATTERN "*.hpp"
    PATTERN "python" EXCLUDE PATTERN "calibration" EXCLUDE PATTERN "commands.hpp" EXCLUDE)
endif()
install(EXPORT papertearTargets NAMESPACE papertear:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/papertearConfig.cmake.in
  ${PROJECT_BINARY_DIR}/papertearConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/papertearConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/papertearConfig.cmake ${PROJECT_BINARY_DIR}/papertearConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/papertear)
