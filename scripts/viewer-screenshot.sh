#!/usr/bin/env bash
# Makes docs/viewer.png (the viewer's panel with the split screen) from docs/viewer/screenshot.script
# in a virtual X server on the CPU device: scripts/viewer-screenshot.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
exec scripts/xvfb-exec.sh "$build/tools/msm/msm" view --device cpu --width 1280 --height 720 \
  --script docs/viewer/screenshot.script
