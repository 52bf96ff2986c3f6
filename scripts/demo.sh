#!/usr/bin/env bash
# The main demo: set-up, Release build of the hprt command only, then
# data/scenes/default.json rendered at its size with both backends into
# out/, the two images compared with `hprt validate image` (heat map
# out/default_diff.png), and a Markdown table of build ms, render ms,
# Mrays/s and the PSNR between the backends.
# Usage: scripts/demo.sh [--no-build] [--threads N]
#   --no-build   skip setup.sh/build.sh (use an existing build)
#   HPRT_BUILD_DIR selects the build directory (default: build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${HPRT_BUILD_DIR:-$root/build}"
do_build=1
threads=0
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) do_build=0 ;;
    --threads) threads="$2"; shift ;;
    *) echo "demo: unknown argument '$1' (usage: demo.sh [--no-build] [--threads N])" >&2; exit 2 ;;
  esac
  shift
done

if [ "$do_build" = 1 ]; then
  "$root/scripts/setup.sh"
  HPRT_BUILD_TARGETS=hprt "$root/scripts/build.sh"  # the demo runs only the hprt command
fi
hprt="$build/src/hprt"
[ -x "$hprt" ] || { echo "demo: $hprt not found (build first)" >&2; exit 2; }

out="$root/out"
mkdir -p "$out"
scene="$root/data/scenes/default.json"

# Value of a numeric or string field in hprt's one-line JSON (no jq needed).
json_field() {  # json key
  printf '%s\n' "$1" | sed -n "s/.*\"$2\":\"\{0,1\}\([^,\"}]*\)\"\{0,1\}[,}].*/\1/p"
}

declare -A build_ms render_ms mrays config used_threads
for backend in embree bvh; do
  json="$("$hprt" render "$scene" --backend "$backend" --threads "$threads" \
          -o "$out/default_$backend.png" --json)"
  build_ms[$backend]="$(json_field "$json" build_ms)"
  render_ms[$backend]="$(json_field "$json" render_ms)"
  mrays[$backend]="$(json_field "$json" mrays_per_s)"
  config[$backend]="$(json_field "$json" config)"
  used_threads[$backend]="$(json_field "$json" threads)"
  size="$(json_field "$json" width)x$(json_field "$json" height)"
  triangles="$(json_field "$json" triangles)"
done

# Same thresholds as tests/render/test_render_golden.cpp between backends: PSNR of at
# least 50 dB, at most 0.1 % of the pixels off by more than 0.01.
pixels=$(( ${size%x*} * ${size#*x} ))
status=0
vjson="$("$hprt" validate image "$out/default_embree.png" "$out/default_bvh.png" \
          --diff "$out/default_diff.png" --min-psnr 50 --max-pixels-over $(( pixels / 1000 )) \
          --json)" || status=$?
if [ "$status" -gt 1 ]; then echo "demo: validate image failed" >&2; exit "$status"; fi
psnr="$(json_field "$vjson" psnr_db)"
[ "$psnr" = "null" ] && psnr="inf (identical)"
pixels_over="$(json_field "$vjson" pixels_over)"
max_error="$(json_field "$vjson" max_error)"
verdict=$([ "$status" = 0 ] && echo pass || echo FAIL)

fmt() { printf '%.1f' "$1"; }
fmt2() { printf '%.2f' "$1"; }
echo
echo "### default.json: $size, $triangles triangles"
echo
echo "| backend | config | threads | build ms | render ms | Mrays/s | PSNR vs embree (dB) |"
echo "|---|---|---:|---:|---:|---:|---:|"
for backend in embree bvh; do
  if [ "$backend" = embree ]; then p="—"; else p="$(printf '%.2f' "$psnr" 2>/dev/null || echo "$psnr")"; fi
  echo "| $backend | ${config[$backend]} | ${used_threads[$backend]} | $(fmt "${build_ms[$backend]}") | $(fmt "${render_ms[$backend]}") | $(fmt2 "${mrays[$backend]}") | $p |"
done
echo
echo "validate image: $pixels_over of $pixels pixels differ by more than 0.01, max error $(printf '%.3f' "$max_error"): $verdict"
echo "images: out/default_embree.png out/default_bvh.png, heat map: out/default_diff.png"
exit "$status"
