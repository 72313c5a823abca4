# The installed-package test (label `package`): installs this build into a scratch prefix,
# then configures, builds and runs tests/consumer against that prefix only. It catches what
# in-tree tests cannot: a header left out of the install, an include path that only works in
# the source tree, a dependency the package config forgets to find.
#
# The consumer is built with this build's compiler and flags, so a sanitizer build links a
# sanitized consumer against its sanitized library.
add_test(NAME papertear/package/install_and_consume
  COMMAND ${CMAKE_COMMAND}
    -DBUILD_DIR=${PROJECT_BINARY_DIR}
    -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/package-test
    -DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_LIST_DIR}
    -DGENERATOR=${CMAKE_GENERATOR}
    -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
    -DBUILD_TYPE=${CMAKE_BUILD_TYPE}
    "-DCXX_FLAGS=${CMAKE_CXX_FLAGS}"
    "-DEXE_LINKER_FLAGS=${CMAKE_EXE_LINKER_FLAGS}"
    -P ${CMAKE_CURRENT_LIST_DIR}/run_consumer_test.cmake)
set_tests_properties(papertear/package/install_and_consume PROPERTIES
  LABELS package
  TIMEOUT 600)
