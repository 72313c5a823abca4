# Script mode (cmake -P) body of the package test; see ConsumerTest.cmake. Every step stops
# the test with a message naming the step that failed.
cmake_minimum_required(VERSION 3.25)

foreach(var BUILD_DIR WORK_DIR CONSUMER_SOURCE_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "package test: ${var} is not set")
  endif()
endforeach()

set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/consumer-build")

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "package test: ${name} failed (${rc})\n${out}\n${err}")
  endif()
  message(STATUS "package test: ${name}: ok")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

# A fresh prefix each time, so a file that a previous build installed cannot hide a missing one.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

run_step("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

foreach(header core/simulation.hpp core/scene.hpp core/world.hpp kernels/parallel.hpp fracture/metrics.hpp
               tools/scene_file.hpp tools/summary.hpp tools/render/mesh_export.hpp)
  if(NOT EXISTS "${prefix}/include/papertear/${header}")
    message(FATAL_ERROR "package test: ${header} was not installed under ${prefix}/include/papertear")
  endif()
endforeach()

run_step("configure consumer" ${CMAKE_COMMAND}
  -S "${CONSUMER_SOURCE_DIR}" -B "${consumer_build}" -G "${GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${prefix}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
  "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}"
  "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
  "-DCMAKE_EXE_LINKER_FLAGS=${EXE_LINKER_FLAGS}")

# The consumer must have found the package we just installed, not some other copy.
file(STRINGS "${consumer_build}/CMakeCache.txt" found_dir REGEX "^papertear_DIR:")
string(REGEX REPLACE "^papertear_DIR:[A-Z]+=" "" found_dir "${found_dir}")
cmake_path(IS_PREFIX prefix "${found_dir}" NORMALIZE found_in_prefix)
if(NOT found_in_prefix)
  message(FATAL_ERROR "package test: the consumer found papertear in '${found_dir}', not under ${prefix}")
endif()

run_step("build consumer" ${CMAKE_COMMAND} --build "${consumer_build}")
run_step("run consumer" "${consumer_build}/app")
message(STATUS "${step_output}")
run_step("run host" "${consumer_build}/host" "${WORK_DIR}/host-out")
message(STATUS "${step_output}")
