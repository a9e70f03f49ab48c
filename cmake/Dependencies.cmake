# Every third-party package comes from Debian bookworm (scripts/install-deps.sh installs them).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(fmt REQUIRED)
find_package(OpenMP REQUIRED)  # Eigen's GEMM threads
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C CXX)
if(FIGNET_BUILD_BULLET_PLUGIN)
  find_package(Bullet REQUIRED)  # CMake's FindBullet: BULLET_INCLUDE_DIRS / BULLET_LIBRARIES
  # Bullet's HACD convex decomposition (libbullet-extras-dev), for non-convex mesh files.
  find_library(BULLET_HACD_LIBRARY NAMES HACD REQUIRED)
  find_package(urdfdom REQUIRED)
  find_package(assimp REQUIRED)
endif()
if(FIGNET_WITH_MPI)
  find_package(MPI REQUIRED COMPONENTS CXX)  # OpenMPI: data-parallel training and evaluation
endif()
if(FIGNET_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(FIGNET_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
