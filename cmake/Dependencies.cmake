# One place for every dependency; all of them come from Debian 12's packages
# (see README: libeigen3-dev libtbb-dev libxsimd-dev libbenchmark-dev catch2 ...).
include(GNUInstallDirs)
find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
find_package(xsimd REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
