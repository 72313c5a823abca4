# Floating point: results must be the same bits on every thread count and instruction set,
# so the compiler may not fuse a*b+c into an FMA (which rounds once instead of twice), and
# -ffast-math is never used (it licenses reassociation and approximate reciprocals).
add_compile_options(-ffp-contract=off -fno-fast-math)
if(NOT PAPERTEAR_ARCH STREQUAL "none")
  add_compile_options(-march=${PAPERTEAR_ARCH})
endif()
set(PAPERTEAR_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # GCC 12 warns about overlapping memcpy inside libstdc++'s own std::string code at -O3
  # (a known false positive of -Wrestrict); the code is the standard library's, not ours.
  list(APPEND PAPERTEAR_WARNINGS -Wno-restrict)
endif()
if(PAPERTEAR_WERROR)
  list(APPEND PAPERTEAR_WARNINGS -Werror)
endif()
