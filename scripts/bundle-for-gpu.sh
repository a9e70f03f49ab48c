#!/usr/bin/env bash
# Builds the CUDA backend's programs and packs them with the shared libraries they need beyond
# the C library, the C++ runtime and CUDA itself, for a GPU machine that has a CUDA driver and
# cuBLAS but none of the Debian packages (docs/gpu.md). Usage:
#   scripts/bundle-for-gpu.sh [OUT_DIR] [CUDA_ARCHITECTURES]     (defaults: .gpu and 90)
# Then on the GPU machine: OUT_DIR/run fignet train --device cuda ...
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-.gpu}"
architectures="${2:-90}"
build=build/gpu

cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFIGNET_WITH_CUDA=ON \
  -DFIGNET_WITH_MPI=OFF -DFIGNET_BUILD_BENCHMARKS=ON -DCMAKE_CUDA_ARCHITECTURES="$architectures" \
  >/dev/null
cmake --build "$build" -j"$(nproc)" --target fignet test_cuda test_nn test_model bench_network

rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
cp "$build/tools/fignet" "$build/tests/test_cuda" "$build/tests/test_nn" "$build/tests/test_model" \
  "$build/tests/bench/bench_network" "$out/bin/"
# Every library the programs load, except those any Linux (glibc, libstdc++) or CUDA machine has.
for program in "$out"/bin/*; do
  ldd "$program" | awk '$3 ~ /^\// {print $3}'
done | sort -u | grep -Ev '/(libc|libm|libdl|librt|libpthread|libstdc\+\+|libgcc_s|ld-linux[^/]*|libcuda|libcudart|libcublas|libcublasLt)\.so' |
  while read -r library; do cp -L "$library" "$out/lib/"; done
cat >"$out/run" <<'RUN'
#!/usr/bin/env bash
# Runs a bundled program with the bundle's libraries: run PROGRAM [ARGS...]
here="$(cd "$(dirname "$0")" && pwd)"
program="$1"
shift
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
exec "$here/bin/$program" "$@"
RUN
chmod +x "$out/run"
du -sh "$out"
