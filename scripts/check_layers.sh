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
  [src/anim]="core io"
  [src/bvh]="core"
  [src/backends]="core bvh"
  [src/render]="core anim bvh backends"
  [validators]="core io bvh backends"
  [bench]="core meshgen io anim bvh backends render validators"
  [src/cli]="core meshgen io anim bvh backends render validators bench"
)
# src/bvh's parts, lowest first.
bvh_parts=(memory input split builders layout intersect traverse refit)

bad=0
for dir in "${!allowed[@]}"; do
  self="${dir#src/}"
  while IFS= read -r line; do
    file="${line%%:*}"
    target="$(sed -E 's/.*#include "([a-z_]+)\/.*/\1/' <<<"$line")"
    [[ "$target" == "$self" ]] && continue
    if [[ " ${allowed[$dir]} " != *" $target "* ]]; then
      echo "check_layers: $file includes $target/, above $dir" >&2
      bad=1
    fi
  done < <(grep -rHE '#include "(core|meshgen|io|anim|bvh|backends|render|cli|validators|bench)/' "$dir" || true)
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
    target="$(sed -E 's/.*#include "bvh\/([a-z_]+)\/.*/\1/' <<<"$line")"
    if (( $(rank "$target") > own )); then
      echo "check_layers: $file includes bvh/$target/, above bvh/$part" >&2
      bad=1
    fi
  done < <(grep -rHE '#include "bvh/[a-z_]+/' "src/bvh/$part" || true)
done
stray=$(find src/bvh -maxdepth 1 -type f)
if [[ -n "$stray" ]]; then echo "check_layers: files outside src/bvh's parts: $stray" >&2; bad=1; fi
if (( bad == 0 )); then echo "check_layers: every include runs down"; fi
exit "$bad"
