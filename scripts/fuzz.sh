#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang, ASan+UBSan) in build-fuzz and
# runs each for FUZZ_SECONDS (default 15) on a temp copy of its seed corpus,
# as many at once as there are cores.
# Exits non-zero on any crash, sanitizer report, leak, timeout or OOM; skips
# (exit 0, with a message) when clang or libFuzzer (libclang-rt-14-dev) is missing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${HPRT_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${FUZZ_SECONDS:-15}"

if ! command -v clang >/dev/null || ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: skipped: clang/clang++ not found" >&2
  exit 0
fi
probe="$(mktemp -d)"
trap 'rm -rf "$probe"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' \
  >"$probe/probe.cpp"
if ! clang++ -fsanitize=fuzzer,address "$probe/probe.cpp" -o "$probe/probe" 2>/dev/null; then
  echo "fuzz.sh: skipped: clang cannot link libFuzzer (install libclang-rt-14-dev)" >&2
  exit 0
fi

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DHPRT_FUZZ=ON -DHPRT_BUILD_TESTS=OFF -DHPRT_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target fuzz_ply fuzz_obj fuzz_scene fuzz_rays

work="$probe/run"
# One fuzzer per core at a time (each is one single-threaded process).
fuzz_one() {  # name: runs it, keeps its log; status in $work/$name.status
  local name="$1" rc=0
  mkdir -p "$work/$name" "$work/artifacts-$name"
  cp "$root/tests/fuzz/corpus/$name/"* "$work/$name/"
  (cd "$work" && "$build/tests/fuzz/fuzz_$name" "$work/$name" \
     -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
     -artifact_prefix="$work/artifacts-$name/" >"$work/$name.log" 2>&1) || rc=$?
  echo "$rc" >"$work/$name.status"
}
names=(ply obj scene rays)
running=0
for name in "${names[@]}"; do
  echo "== fuzz_$name (${seconds}s)"
  fuzz_one "$name" &
  running=$((running + 1))
  if (( running >= $(nproc) )); then wait -n || true; running=$((running - 1)); fi
done
wait
status=0
for name in "${names[@]}"; do
  if [[ "$(cat "$work/$name.status")" != 0 ]]; then
    status=1
    tail -n 60 "$work/$name.log"
    mkdir -p "$build/fuzz-artifacts"
    cp "$work/artifacts-$name/"* "$build/fuzz-artifacts/" 2>/dev/null || true
    echo "fuzz.sh: fuzz_$name FAILED; reproducer(s) copied to $build/fuzz-artifacts/" >&2
  else
    echo "fuzz_$name: $(grep -E '^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)' "$work/$name.log" | tr '\n' ' ')"
  fi
done
exit $status
