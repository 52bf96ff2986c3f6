#!/usr/bin/env bash
# Regenerates the golden images data/golden/<scene>.png that
# tests/render/test_render_golden.cpp compares every backend against: each scene of
# data/scenes (except default.json, the demo scene) rendered small with the
# Embree backend. Run it ONLY when a change of the rendered images is
# intended (shading, camera, scene files), and say so in the commit.
# Usage: scripts/update_golden.sh [path/to/hprt]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
hprt="${1:-${HPRT_BUILD_DIR:-$root/build}/src/hprt}"
if [ ! -x "$hprt" ]; then
  echo "update_golden: $hprt not found; build first (scripts/build.sh) or pass its path" >&2
  exit 2
fi
# Sizes must match tests/render/test_render_golden.cpp.
declare -A sizes=(
  [single_6mm]="160 120"
  [single_13mm]="160 120"
  [combo]="160 120"
  [hires]="192 108"
)
mkdir -p "$root/data/golden"
for scene in single_6mm single_13mm combo hires; do
  read -r w h <<<"${sizes[$scene]}"
  "$hprt" render "$root/data/scenes/$scene.json" --backend embree --width "$w" --height "$h" \
    -o "$root/data/golden/$scene.png"
done
