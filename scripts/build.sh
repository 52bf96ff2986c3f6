#!/usr/bin/env bash
# Configures and builds hprt (Release) into build/; extra args go to cmake.
# HPRT_BUILD_TARGETS (space-separated) builds only those targets, e.g. "hprt"
# for the demo; default: everything, tests included.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${HPRT_BUILD_DIR:-$root/build}"
# Ninja for a new build directory where it is installed (scripts/setup.sh).
generator=()
if command -v ninja >/dev/null && [[ ! -f "$build/CMakeCache.txt" ]]; then generator=(-G Ninja); fi
cmake "${generator[@]}" -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
targets=()
for t in ${HPRT_BUILD_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$build" -j "$(nproc)" "${targets[@]}"
