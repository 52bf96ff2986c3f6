#!/usr/bin/env bash
# Submits the Slurm job array that renders frames A..B-1 of an animated scene
# in chunks (scripts/cluster/render-array.sbatch; docs/CLUSTER.md):
#
#   submit.sh [--array SPEC] SCENE A:B CHUNK OUT [RENDER_OPTION...]
#
# checks the parameters, submits one array task per chunk of CHUNK frames
# (--array=0-N; --array SPEC submits only those tasks, e.g. "4" or "1,3" or
# "0-9%2") and prints the job id on stdout. Frames already rendered in OUT for
# the same scene file and render options are skipped by their task, so the
# same command resubmits whatever is missing. Task logs go to
# OUT/logs/hprt-frames_<job>_<task>.log.
#
# Environment: HPRT_BIN (hprt binary, default hprt on PATH; must be reachable
# at the same path on the compute nodes), HPRT_PATTERN (default
# frame_%04d.png), HPRT_CPUS (cores per task, default 1; hprt gets
# --threads HPRT_CPUS unless the render options set --threads),
# HPRT_SBATCH_OPTS (more sbatch options, e.g. "--partition=render
# --time=01:00:00"), and Slurm's own SBATCH_* variables. Exit code 2: bad
# parameters (nothing submitted).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
sbatch_script="$here/render-array.sbatch"
die2() { echo "submit: $*" >&2; exit 2; }

array=""
while [ $# -gt 0 ]; do
  case "$1" in
    --array) [ $# -ge 2 ] || die2 "--array needs a task list"; array="$2"; shift 2 ;;
    --array=*) array="${1#--array=}"; shift ;;
    --) shift; break ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) die2 "unknown option '$1' (render options go after OUT)" ;;
    *) break ;;
  esac
done
[ $# -ge 4 ] || die2 "usage: submit.sh [--array SPEC] SCENE A:B CHUNK OUT [RENDER_OPTION...]"
scene="$1" frames="$2" chunk="$3" out="$4"
shift 4
# Absolute paths: the tasks run in the submit directory, but need not share
# its relative view of the file system.
[ -f "$scene" ] || die2 "scene '$scene' is not a readable file"
scene="$(realpath "$scene")"
out="$(realpath -m "$out")"
if [ -n "${HPRT_BIN:-}" ] && [[ "$HPRT_BIN" == */* ]]; then
  HPRT_BIN="$(realpath -m "$HPRT_BIN")"
  export HPRT_BIN
fi
cpus="${HPRT_CPUS:-1}"
[[ "$cpus" =~ ^[1-9][0-9]{0,4}$ ]] || die2 "HPRT_CPUS '$cpus' is not an integer >= 1"
command -v sbatch >/dev/null || die2 "sbatch not found: run this on a Slurm submit host"

# The same checks the tasks make, and how many tasks there are.
plan="$(SLURM_CPUS_PER_TASK="$cpus" HPRT_PLAN=1 bash "$sbatch_script" "$scene" "$frames" "$chunk" "$out" "$@")" ||
  exit $?
ntasks="$(sed -n 's/^tasks=//p' <<<"$plan")"
missing="$(sed -n 's/^missing=//p' <<<"$plan")"

# A JSON scene states its frame count: catch B past the end before submitting.
if [[ "$scene" == *.json ]] && [ -x /usr/bin/python3 ]; then
  n="$(/usr/bin/python3 -c 'import json,sys
try: print(int(json.load(open(sys.argv[1]))["animation"]["frames"]))
except Exception: print("")' "$scene")"
  end="${frames#*:}"
  if [ -n "$n" ] && ((10#$end > n)); then
    die2 "frames '$frames' go past the animation's $n frames (0:$n) in $scene"
  fi
fi

mkdir -p "$out/logs"
[ -n "$array" ] || array="0-$((ntasks - 1))"
read -r -a extra <<<"${HPRT_SBATCH_OPTS:-}"
job="$(sbatch --parsable --array="$array" --cpus-per-task="$cpus" \
  --output="$out/logs/%x_%A_%a.log" "${extra[@]+"${extra[@]}"}" \
  "$sbatch_script" "$scene" "$frames" "$chunk" "$out" "$@")"
job="${job%%;*}"  # "id;cluster" on multi-cluster sites
nmissing=$(wc -w <<<"$missing")
echo "submit: job $job: tasks $array of $ntasks (frames $frames, $chunk per task), $nmissing frame(s) to render${missing:+: $missing}" >&2
echo "$job"
