# One place for every dependency; all of them come from Debian 12's packages
# (see README: libeigen3-dev libtbb-dev libxsimd-dev libbenchmark-dev catch2 ...).
include(GNUInstallDirs)
find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
find_package(xsimd REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)

# Debian 12's xsimd 8.1 package names "xtl" in its link interface without finding it, so
# every executable would link -lxtl, which does not exist. xsimd's headers do not need xtl:
# drop the stray name unless a real xtl target exists. (papertearConfig.cmake.in does the
# same for consumers of the installed package.)
if(TARGET xsimd AND NOT TARGET xtl)
  get_target_property(_xsimd_libs xsimd INTERFACE_LINK_LIBRARIES)
  if(_xsimd_libs)
    list(REMOVE_ITEM _xsimd_libs xtl)
    set_property(TARGET xsimd PROPERTY INTERFACE_LINK_LIBRARIES "${_xsimd_libs}")
  endif()
  unset(_xsimd_libs)
endif()
