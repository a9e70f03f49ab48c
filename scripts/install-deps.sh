#!/usr/bin/env bash
# Installs every build and test dependency from Debian bookworm's packages.
# Idempotent: packages already present are left as they are. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libbullet-dev libbullet-extras-dev
  libeigen3-dev libdnnl-dev
  liburdfdom-dev libtinyxml-dev libconsole-bridge-dev
  libassimp-dev assimp-testmodels libcgal-dev libmeshoptimizer-dev
  libhdf5-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
  chromium
  clang libclang-rt-14-dev libomp-14-dev
)
# Node.js and npm from Debian unless some other install already provides both (Node.js builds
# that bundle npm conflict with Debian's npm package).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} Debian packages already installed"
else
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${packages[@]}"
fi

# The HTML report's player: three.js, esbuild (bundles it at build time) and playwright-core (the
# report's browser test), pinned by web/package-lock.json. Reinstalled when the lock changes.
web="$(cd "$(dirname "$0")/.." && pwd)/web"
stamp="$web/node_modules/.package-lock.json"
if [ ! -f "$stamp" ] || [ "$web/package-lock.json" -nt "$stamp" ]; then
  echo "install-deps: npm ci in web/"
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "install-deps: web/node_modules up to date"
fi
