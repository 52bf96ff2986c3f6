#!/usr/bin/env bash
# Checks the layering of the code: each folder includes only the folders it
# builds on (below), and inside src/bvh each part only the parts before it.
# Prints every include that runs back up; exit 1 if there is one.
# Usage: check_layers.sh [REPO_ROOT]
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root"

# folder: the folders its files may include (besides itself).
declare -A allowed=(
  [src/core]=""
  [src/meshgen]="core"
  [src/io]="core meshgen"
  [src/image_oiio]="core io"
  [src/anim]="core io"
  [src/bvh]="core"
  [src/backends]="core bvh"
  [src/workload]="core backends"
  [src/render]="core anim bvh backends"
  [validators]="core io bvh backends workload"
  [bench]="core meshgen io anim bvh backends workload render validators"
  [src/raycasting]=""
  [src/api]="core meshgen io anim bvh backends workload render validators"
  [src/cli]="core meshgen io anim bvh backends workload render validators bench"
)
# src/bvh's parts, lowest first.
bvh_parts=(memory input split builders layout intersect traverse refit)

layers="core|meshgen|io|image_oiio|anim|bvh|backends|workload|render|api|raycasting|cli|validators|bench"
bad=0
for dir in "${!allowed[@]}"; do
  # "file:#include \"target/" per include of another layer; one awk per folder
  # (a process per include line took seconds).
  if ! grep -rHoE "#include \"($layers)/" "$dir" |
      awk -v self="${dir#src/}" -v ok=" ${allowed[$dir]} " -v dir="$dir" '
        { split($0, p, ":#include \""); t = p[2]; sub(/\/$/, "", t)
          if (t != self && index(ok, " " t " ") == 0) {
            print "check_layers: " p[1] " includes " t "/, above " dir > "/dev/stderr"; bad = 1 } }
        END { exit bad }'; then
    bad=1
  fi
done

rank() {
  local i
  for i in "${!bvh_parts[@]}"; do [[ "${bvh_parts[$i]}" == "$1" ]] && echo "$i" && return; done
  echo 99
}
for part in "${bvh_parts[@]}"; do
  [[ -d src/bvh/$part ]] || { echo "check_layers: src/bvh/$part is missing" >&2; bad=1; continue; }
  own=$(rank "$part")
  while IFS= read -r line; do
    file="${line%%:*}"
    target="${line##*#include \"bvh/}"
    target="${target%/}"
    if (( $(rank "$target") > own )); then
      echo "check_layers: $file includes bvh/$target/, above bvh/$part" >&2
      bad=1
    fi
  done < <(grep -rHoE '#include "bvh/[a-z_0-9]+/' "src/bvh/$part" || true)
done
stray=$(find src/bvh -maxdepth 1 -type f)
if [[ -n "$stray" ]]; then echo "check_layers: files outside src/bvh's parts: $stray" >&2; bad=1; fi
if (( bad == 0 )); then echo "check_layers: every include runs down"; fi
exit "$bad"
