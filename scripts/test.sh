#!/usr/bin/env bash
# The README's test command (and CI's, via .ci/run): set-up, Release build,
# the whole CTest suite, the Slurm job-array test on a one-node cluster it
# starts itself (tests/cluster/test_slurm_array.sh, needs root, about 30 s);
# then, unless HPRT_TEST_QUICK=1, the reliability passes: ASan+UBSan over the
# unit tests, TSan over the parallel tests (scripts/sanitize.sh) and each
# libFuzzer target for FUZZ_SECONDS (default 15, about a minute in all;
# scripts/fuzz.sh skips itself without clang/libFuzzer).
# Prints each stage's wall time; stops at the first failing stage.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
times=()
stage() {  # name command...
  local name="$1" start=$SECONDS
  shift
  echo "=== test.sh: $name" >&2
  "$@"
  times+=("$(printf '%-26s %5d s' "$name" $((SECONDS - start)))")
}
report() {
  echo "=== test.sh: stage times" >&2
  for t in "${times[@]}"; do echo "  $t" >&2; done
}
trap report EXIT

stage "setup" "$root/scripts/setup.sh"
stage "Release build" "$root/scripts/build.sh"
release_ctest() {
  cd "${HPRT_BUILD_DIR:-$root/build}"
  ctest --output-on-failure -j "$(nproc)" --timeout 600
}
stage "Release ctest" release_ctest
stage "Slurm cluster" "$root/tests/cluster/test_slurm_array.sh" "${HPRT_BUILD_DIR:-$root/build}/src/hprt"
if [[ "${HPRT_TEST_QUICK:-0}" == 1 ]]; then
  echo "test.sh: HPRT_TEST_QUICK=1: sanitizer and fuzz passes skipped" >&2
  exit 0
fi
stage "ASan+UBSan (build+tests)" "$root/scripts/sanitize.sh" --asan
stage "TSan (build+tests)" "$root/scripts/sanitize.sh" --tsan
stage "fuzz (build+runs)" env FUZZ_SECONDS="${FUZZ_SECONDS:-15}" "$root/scripts/fuzz.sh"
