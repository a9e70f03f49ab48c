# Warnings and target-architecture flags shared by every target of the project.
add_library(fignet_compile_options INTERFACE)
target_compile_options(fignet_compile_options INTERFACE -Wall -Wextra)

# x86-64-v3 (AVX2/FMA) measured ~30% faster for Eigen GEMM than -march=native on the
# project's Zen 3 machines (the znver3 tuning hurts); FIGNET_PORTABLE builds for any x86-64.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  if(FIGNET_PORTABLE)
    target_compile_options(fignet_compile_options INTERFACE -march=x86-64)
  else()
    target_compile_options(fignet_compile_options INTERFACE -march=x86-64-v3)
  endif()
endif()
set(CMAKE_CXX_FLAGS_RELEASE "-O3 -DNDEBUG")
set(CMAKE_CXX_FLAGS_RELWITHDEBINFO "-O3 -g -DNDEBUG")
