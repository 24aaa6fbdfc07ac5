#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages), then configures and builds nbvh into build/.
# Used by demo.sh and test.sh; safe to run again (apt and the build are incremental).
set -euo pipefail
cd "$(dirname "$0")/.."
PKGS=(build-essential cmake ninja-build pkg-config git
      libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers glslc glslang-tools
      libglm-dev libtinygltf-dev libstb-dev libtinyexr-dev nlohmann-json3-dev libcli11-dev libmeshoptimizer-dev
      python3-matplotlib
      libgtest-dev libglfw3-dev libimgui-dev xvfb xauth)
missing=()
for p in "${PKGS[@]}"; do dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
BUILD_TYPE=${NBVH_BUILD_TYPE:-Release}
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" ${NBVH_CMAKE_ARGS:-} >/dev/null
cmake --build build -j"$(nproc)"
