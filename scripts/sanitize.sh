#!/usr/bin/env bash
# Sanitizer passes: builds build-asan (-DHPRT_SANITIZE=address: ASan + UBSan,
# UB aborts) and runs the whole CTest suite there with leak detection on.
# `--tsan` also builds build-tsan (-DHPRT_SANITIZE=thread) and runs the parallel
# tests; that part is NOT YET ENABLED by default: as of this writing it reports
# 2 races on memory freed by the main thread and last read by a TBB worker whose
# stack TSan cannot restore (likely uninstrumented-libtbb false positives; not
# yet triaged), so it fails.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="$(nproc)"

asan="${HPRT_ASAN_BUILD_DIR:-$root/build-asan}"
# Only `hprt` and the test executables (tests/test_*.cpp, one target each).
tests=(hprt)
for f in "$root"/tests/test_*.cpp; do tests+=("$(basename "$f" .cpp)"); done
cmake -S "$root" -B "$asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHPRT_SANITIZE=address \
  -DHPRT_BUILD_BENCH=OFF >/dev/null
cmake --build "$asan" -j "$jobs" --target "${tests[@]}"
(
  cd "$asan"
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=0" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    ctest --output-on-failure -j "$jobs" --timeout 900
)

if [[ "${1:-}" == "--tsan" ]]; then
  tsan="${HPRT_TSAN_BUILD_DIR:-$root/build-tsan}"
  cmake -S "$root" -B "$tsan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHPRT_SANITIZE=thread \
    -DHPRT_BUILD_BENCH=OFF >/dev/null
  cmake --build "$tsan" -j "$jobs" --target hprt test_builder_parallel test_bvh_backend \
    test_whitted test_render_golden
  (
    cd "$tsan"
    TSAN_OPTIONS="halt_on_error=1:suppressions=$root/tests/sanitizers/tsan.supp" \
      ctest --output-on-failure -j "$jobs" --timeout 1800 \
      -R "BuilderParallel|BvhBackend|Whitted|RenderGolden"
  )
fi
