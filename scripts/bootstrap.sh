#!/usr/bin/env bash
# Installs the Debian 12 packages msm builds and tests with, when they are missing.
# Only Debian's archive is used. Runs apt-get as root, or through sudo.
set -euo pipefail

packages=(
  cmake ninja-build g++ make pkg-config git
  libglm-dev libeigen3-dev libglpk-dev
  libvulkan-dev glslc spirv-tools mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  libassimp-dev libembree-dev libopenexr-dev libstb-dev libtbb-dev zlib1g-dev libdeflate-dev valgrind
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin  # MPI ranks of msm evaluate (Open MPI)
  clang-format clang-tidy  # .ci/check-format (clang-format 14) and .ci/tidy
  clang-16 libclang-rt-16-dev  # the fuzz targets (make fuzz, tests/fuzz; clang 16: C++20 aggregate init with parentheses)
  glmark2-data  # real meshes for the import tests (the bunny, 9 MB)
  blender-data  # CC0 equirectangular HDR light probes (studiolights/world) for the light-probe tests
  libglfw3-dev libimgui-dev xvfb xauth  # msm view (GLFW, Dear ImGui) and its tests in a virtual X server
  fonts-dejavu-core  # the font of msm view's panel (Greek letters of the parameter help)
  assimp-testmodels  # Khronos glTF samples (2CylinderEngine, BoxTextured, ...) for the real-model tests (74 MB)
  python3-matplotlib  # msm report's charts
  nodejs chromium  # the three.js package in web/, and the browser tests of it and of msm report's page (headless)
)
command -v npm >/dev/null || packages+=(npm) # a nodejs from elsewhere (NodeSource) brings its own npm

# web/'s npm packages as its lockfile pins them (three, playwright-core, ...), again when the lockfile changes.
web_packages() {
  local web
  web="$(dirname "$0")/../web"
  [[ "$web/node_modules/.package-lock.json" -nt "$web/package-lock.json" ]] || (cd "$web" && npm ci --no-audit --no-fund)
}

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "bootstrap: all ${#packages[@]} packages present"
  web_packages
  exit 0
fi

echo "bootstrap: installing ${missing[*]}"
if [[ $(id -u) -eq 0 ]]; then sudo=(); elif command -v sudo >/dev/null; then sudo=(sudo); else
  echo "bootstrap: need root or sudo to install: ${missing[*]}" >&2; exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
web_packages
