#!/usr/bin/env bash
# One set-up for a fresh Debian 12 machine: installs the missing packages (as root), then
# configures and builds vplview into build/ (or $VPLVIEW_BUILD). Safe to run again.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${VPLVIEW_BUILD:-$here/build}

packages=(build-essential cmake ninja-build pkg-config ccache python3
  libembree-dev libglfw3-dev libosmesa6-dev libglm-dev libtinygltf-dev libopenexr-dev
  libtbb-dev libnanoflann-dev libimgui-dev libcli11-dev libstb-dev libgtest-dev
  libbenchmark-dev nlohmann-json3-dev xvfb xauth libgl1-mesa-dri
  clang libclang-rt-14-dev)  # clang + its libFuzzer runtime (only Recommended by clang-14): the fuzz test
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  if [ "$(id -u)" != 0 ]; then
    echo "setup: missing Debian packages and not root: run as root (or: sudo $0)" >&2; exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The Khronos glTF validator for the scene tests (optional: the test skips without it).
if command -v npm >/dev/null && [ ! -d "$build/tools/node_modules/gltf-validator" ]; then
  mkdir -p "$build/tools"
  npm install --silent --no-audit --no-fund --prefix "$build/tools" gltf-validator@2.0.0-dev.3.10 >/dev/null 2>&1 ||
    echo "setup: warning: could not install gltf-validator from npm; its test will be skipped" >&2
fi

cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="${VPLVIEW_BUILD_TYPE:-Release}" ${VPLVIEW_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" --parallel "$(nproc)"
