# Warnings and target-architecture flags shared by every target of the project, C++ sources only
# (nvcc takes neither). Every target that compiles the project's headers links this: Eigen's
# alignment, and with it the layout of and the allocator behind the core's types, follows the
# instruction set, so a source built without these flags must not share objects with one built
# with them (fignet_core also fixes Eigen's alignment for code outside the project).
add_library(fignet_compile_options INTERFACE)
target_compile_options(fignet_compile_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra>)

# x86-64-v3 (AVX2/FMA) measured ~30% faster for Eigen GEMM than -march=native on the
# project's Zen 3 machines (the znver3 tuning hurts); FIGNET_PORTABLE builds for any x86-64.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  if(FIGNET_PORTABLE)
    target_compile_options(fignet_compile_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-march=x86-64>)
  else()
    target_compile_options(fignet_compile_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-march=x86-64-v3>)
  endif()
endif()
set(CMAKE_CXX_FLAGS_RELEASE "-O3 -DNDEBUG")
# RelWithDebInfo is the sanitizer preset's build type. -O2 with line tables only (-g1) compiled
# three of the heaviest sources under ASan + UBSan in 0.48-0.53 of the time -O3 -g took (Zen 3,
# 2026-11-29), and -O2 runs as fast; backtraces keep their files and lines.
set(CMAKE_CXX_FLAGS_RELWITHDEBINFO "-O2 -g1 -DNDEBUG")
