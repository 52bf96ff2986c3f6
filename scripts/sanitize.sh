#!/usr/bin/env bash
# Sanitizer passes (part of scripts/test.sh). Usage: sanitize.sh [--asan] [--tsan]
# (no argument: both).
#   --asan  build-asan (-DHPRT_SANITIZE=address: ASan + UBSan, UB aborts, -O1 -g1):
#           `hprt` and every layer's test executable (hprt_tests_*), the whole CTest suite,
#           leak detection on.
#   --tsan  build-tsan (-DHPRT_SANITIZE=thread, -O2 -g1): `hprt` and
#           hprt_tests_tsan, the parallel suites (parallel and Morton
#           builders, tree statistics, buffer cache, refit, bvh backend,
#           renderer, concurrency, signal), run under TSan with tests/sanitizers/tsan.supp. Debian's
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

# ASan+UBSan at -O1, as the sanitizers' own documentation advises: it halves
# the instrumented compile (CLI11 and GoogleTest code above all) against -O2
# for little more test time. TSan at -O2: at -O1 its suites ran several
# times longer (more memory accesses left to instrument and check). -g1 (line
# tables) is enough for the reports. Ninja where it is installed
# (scripts/setup.sh installs it).
configure() {  # build-dir sanitizer optimisation
  local generator=()
  if command -v ninja >/dev/null && [[ ! -f "$1/CMakeCache.txt" ]]; then generator=(-G Ninja); fi
  cmake "${generator[@]}" -S "$root" -B "$1" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$3 -g1 -DNDEBUG" -DHPRT_SANITIZE="$2" \
    -DHPRT_BUILD_BENCH=OFF >/dev/null
}

if [[ $do_asan == 1 ]]; then
  asan="${HPRT_ASAN_BUILD_DIR:-$root/build-asan}"
  targets=(hprt)
  for d in "$root"/tests/*/; do
    compgen -G "$d/test_*.cpp" >/dev/null && targets+=("hprt_tests_$(basename "$d")")
  done
  configure "$asan" address -O1
  start=$SECONDS
  cmake --build "$asan" -j "$jobs" --target "${targets[@]}"
  echo "sanitize.sh: ASan+UBSan build: $((SECONDS - start)) s"
  start=$SECONDS
  (
    cd "$asan"
    # Every suite, but of the backend parity sweep (builder x test x ray
    # kind, 90 cases, 57 % of this pass's time) only the parallel builder's
    # cases: the traversal and both tests are the same code for every
    # builder, each builder's own suite runs here in full, and the Release
    # pass runs the whole sweep. A failed test runs once more: on these VMs
    # LeakSanitizer's tracer thread now and then dies at exit ("Tracer caught
    # signal 11 ... LeakSanitizer has encountered a fatal error") after the
    # test itself passed; a real ASan, UBSan or leak report fails both runs.
    ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:check_initialization_order=1" \
      UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
      ctest --output-on-failure -j "$jobs" --timeout 900 --repeat until-pass:2 \
      -E 'BackendParity\.BvhIsNeverWrong/(sweep|presorted|binned|morton)_'
  )
  echo "sanitize.sh: ASan+UBSan tests: $((SECONDS - start)) s"
fi

if [[ $do_tsan == 1 ]]; then
  tsan="${HPRT_TSAN_BUILD_DIR:-$root/build-tsan}"
  # The parallel suites, in one executable of the files that hold them
  # (hprt_tests_tsan, tests/CMakeLists.txt), so the TSan build compiles no
  # other test. Left out:
  # UpdateStrategies (under TSan its two cheapest cases ran > 5 min, 20k-
  # triangle sphere, 3 updates, without a report; its parallel refit/rebuild
  # paths are Refit.DeterministicForAnyThreadCount's).
  # TSan slows our instrumented build/traversal code 20-50x, and TBB workers
  # spin on 2 oversubscribed cores, so suites with large meshes or 7/16-thread
  # sweeps take minutes per case (BuilderParallel.EqualsBinnedForAnyThreadCount,
  # BuilderMorton.SameTreeForAnyThreadCountAndCutoff and
  # SahCostWithinBoundOfBinned, Refit.SahCostMatchesTreeStatsAfterBuild,
  # RenderGolden's bvh cases, BvhBackend.OneAndTwoThreadsIdentical). The cases
  # below still run every parallel path (parallel binning/partition/stitching,
  # the Morton radix sort and subtree tasks, tree statistics, parallel refit,
  # tile scheduler, concurrent callers, the build-buffer cache's mutex under
  # std::threads, the backends' lock-free query clock, signal handling); the
  # rest run in the Release and ASan passes.
  run=(
    "BuilderParallel.*" "BuilderMorton.*" "TreeStats.*" "BuildArray.*" "HugeBufferCache.*"
    "BusyClock.*"
    Refit.DeterministicForAnyThreadCount Refit.EmptyAndSingleLeafTrees
    Refit.ReportsATriangleThatBecameInvalid
    BvhBackend.InfoReportsTheBuild BvhBackend.EmptySceneAndInvalidRaysMiss
    BvhBackend.RebuildingUpdateEqualsAFreshBuild
    "Whitted.*" "Scenes/*embree*" "Concurrency.*" "Signal.*"
  )
  skip=(
    "*EqualsBinnedForAnyThreadCount" "*SmallCutoffStitchesSubtreesExactly"
    "*EqualsBinnedForEveryBinCount" "*SameTreeForAnyThreadCountAndCutoff"
    "*SahCostWithinBoundOfBinned"
  )
  join() { local IFS=:; echo "$*"; }
  configure "$tsan" thread -O2
  start=$SECONDS
  cmake --build "$tsan" -j "$jobs" --target hprt hprt_tests_tsan
  echo "sanitize.sh: TSan build: $((SECONDS - start)) s"
  start=$SECONDS
  # One process per group: TSan's record of reported (and suppressed) racy
  # addresses grows through a process and is searched on every report.
  status=0
  for group in "${run[@]}"; do
    echo "== TSan: $group"
    if ! (cd "$tsan/tests" &&
          TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$root/tests/sanitizers/tsan.supp" \
            ./hprt_tests_tsan --gtest_filter="$group-$(join "${skip[@]}")" --gtest_brief=1); then
      status=1
      echo "sanitize.sh: TSan: $group FAILED" >&2
    fi
  done
  echo "sanitize.sh: TSan tests: $((SECONDS - start)) s"
  exit $status
fi
