#!/usr/bin/env bash
# Sanitizer passes (part of scripts/test.sh). Usage: sanitize.sh [--asan] [--tsan]
# (no argument: both).
#   --asan  build-asan (-DHPRT_SANITIZE=address: ASan + UBSan, UB aborts, -O2 -g1):
#           `hprt` and every layer's test executable (hprt_tests_*), the whole CTest suite,
#           leak detection on.
#   --tsan  build-tsan (-DHPRT_SANITIZE=thread, -O2 -g1): `hprt` and the layers
#           with parallel code, whose parallel suites (parallel and Morton
#           builders, tree statistics, buffer cache, refit, bvh backend,
#           renderer, concurrency, signal) run under TSan with tests/sanitizers/tsan.supp. Debian's
#           libtbb is not instrumented: tests/sanitizers/tbb_tsan_sync.cpp makes
#           TSan see oneTBB's joins, and tsan.supp says what is suppressed and why.
# HPRT_ASAN_BUILD_DIR / HPRT_TSAN_BUILD_DIR override the build directories.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="$(nproc)"
do_asan=0
do_tsan=0
for arg in "$@"; do
  case "$arg" in
    --asan) do_asan=1 ;;
    --tsan) do_tsan=1 ;;
    *) echo "sanitize.sh: unknown argument '$arg' (usage: sanitize.sh [--asan] [--tsan])" >&2
       exit 2 ;;
  esac
done
if [[ $do_asan == 0 && $do_tsan == 0 ]]; then do_asan=1; do_tsan=1; fi

# -O2 keeps the suites fast; -g1 (line tables) is enough for the reports.
configure() {  # build-dir sanitizer
  cmake -S "$root" -B "$1" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DHPRT_SANITIZE="$2" \
    -DHPRT_BUILD_BENCH=OFF >/dev/null
}

if [[ $do_asan == 1 ]]; then
  asan="${HPRT_ASAN_BUILD_DIR:-$root/build-asan}"
  targets=(hprt)
  for d in "$root"/tests/*/; do
    compgen -G "$d/test_*.cpp" >/dev/null && targets+=("hprt_tests_$(basename "$d")")
  done
  configure "$asan" address
  start=$SECONDS
  cmake --build "$asan" -j "$jobs" --target "${targets[@]}"
  echo "sanitize.sh: ASan+UBSan build: $((SECONDS - start)) s"
  start=$SECONDS
  (
    cd "$asan"
    ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:check_initialization_order=1" \
      UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
      ctest --output-on-failure -j "$jobs" --timeout 900
  )
  echo "sanitize.sh: ASan+UBSan tests: $((SECONDS - start)) s"
fi

if [[ $do_tsan == 1 ]]; then
  tsan="${HPRT_TSAN_BUILD_DIR:-$root/build-tsan}"
  # The parallel suites, per layer executable. Left out:
  # UpdateStrategies (under TSan its two cheapest cases ran > 5 min, 20k-
  # triangle sphere, 3 updates, without a report; its parallel refit/rebuild
  # paths are Refit.DeterministicForAnyThreadCount's).
  # TSan slows our instrumented build/traversal code 20-50x, and TBB workers
  # spin on 2 oversubscribed cores, so suites with large meshes or 7/16-thread
  # sweeps take minutes per case (measured: BuilderParallel.EqualsBinnedForAny-
  # ThreadCount 205 s, BuilderMorton.SameTreeForAnyThreadCountAndCutoff 340 s,
  # BuilderMorton.SahCostWithinBoundOfBinned 72 s,
  # Refit.SahCostMatchesTreeStatsAfterBuild > 100 s,
  # RenderGolden bvh cases > 90 s each, BvhBackend.OneAndTwoThreadsIdentical
  # > 150 s). Per suite, the cases below still run
  # every parallel path (parallel binning/partition/stitching, the Morton
  # radix sort and subtree tasks, tree statistics, parallel refit,
  # tile scheduler, concurrent callers, the build-buffer cache's mutex
  # under std::threads); the rest run in the
  # Release and ASan passes.
  declare -A filter=(
    [hprt_tests_bvh]="BuilderParallel.*:BuilderMorton.*:TreeStats.*:BuildArray.*:HugeBufferCache.*:Refit.DeterministicForAnyThreadCount:Refit.EmptyAndSingleLeafTrees:Refit.ReportsATriangleThatBecameInvalid:-*EqualsBinnedForAnyThreadCount:*SmallCutoffStitchesSubtreesExactly:*EqualsBinnedForEveryBinCount:*SameTreeForAnyThreadCountAndCutoff:*SahCostWithinBoundOfBinned"
    [hprt_tests_backends]="BvhBackend.InfoReportsTheBuild:BvhBackend.EmptySceneAndInvalidRaysMiss:BvhBackend.RebuildingUpdateEqualsAFreshBuild"
    [hprt_tests_render]="Whitted.*:Scenes/*embree*"
    [hprt_tests_validators]="Concurrency.*"
    [hprt_tests_cli]="Signal.*"
  )
  configure "$tsan" thread
  start=$SECONDS
  cmake --build "$tsan" -j "$jobs" --target hprt "${!filter[@]}"
  echo "sanitize.sh: TSan build: $((SECONDS - start)) s"
  start=$SECONDS
  status=0
  for t in "${!filter[@]}"; do
    echo "== TSan: $t"
    if ! (cd "$tsan/tests" &&
          TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$root/tests/sanitizers/tsan.supp" \
            "./$t" --gtest_filter="${filter[$t]}" --gtest_brief=1); then
      status=1
      echo "sanitize.sh: TSan: $t FAILED" >&2
    fi
  done
  echo "sanitize.sh: TSan tests: $((SECONDS - start)) s"
  exit $status
fi
