#!/usr/bin/env bash
# Installs the build tree into a temporary prefix and builds and runs tests/downstream against it
# twice: with the header-only math alone, every other package msm uses hidden from CMake, and with
# every component (the renderer's and the viewer's where the build has them: with_renderer, ON by
# default, the build's MSM_BUILD_VULKAN).
set -euo pipefail
build_dir=$1; source_dir=$2; with_renderer=${3:-ON}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"

# The packages of msm's components other than math (their find_dependency calls in msmConfig.cmake).
hidden=(Eigen3 GLPK fmt OpenEXR libdeflate assimp nlohmann_json embree TBB Vulkan glfw3)
math_only=()
for package in "${hidden[@]}"; do math_only+=("-DCMAKE_DISABLE_FIND_PACKAGE_$package=ON"); done

consumer() { # name, cmake arguments...
  local name=$1; shift
  cmake -S "$source_dir/tests/downstream" -B "$work/$name" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" "$@" \
    > "$work/$name.configure.log" 2>&1 || { echo "$name: configure failed"; cat "$work/$name.configure.log"; exit 1; }
  cmake --build "$work/$name" > "$work/$name.build.log" 2>&1 || { echo "$name: build failed"; cat "$work/$name.build.log"; exit 1; }
  "$work/$name/downstream"
}
consumer math -DMSM_DOWNSTREAM_FULL=OFF "${math_only[@]}"
test -s "$work/math/shader.spv"
consumer full -DMSM_DOWNSTREAM_FULL=ON -DMSM_DOWNSTREAM_RENDER="$with_renderer"
