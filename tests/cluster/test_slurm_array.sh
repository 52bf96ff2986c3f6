#!/usr/bin/env bash
# End-to-end test of scripts/cluster/ on a real, throw-away, one-node Slurm
# cluster that this script starts itself:
#
#   tests/cluster/test_slurm_array.sh /path/to/hprt
#
# Starts munged (generated key), slurmctld and slurmd (generated slurm.conf:
# one node with this machine's CPUs, proctrack/linuxproc, task/none, free
# ports on 127.0.0.1, all state in a temporary directory, no systemd), then:
#  1. submits data/scenes/anim_wave.json frames 0:8 in chunks of 3 (3 array
#     tasks, 96x72) with scripts/cluster/submit.sh and checks the frames are
#     byte-identical to one `hprt render --frames 0:8` run, the stamps and
#     per-task records, and the merged table;
#  2. loses a frame, leaves a killed task's traces (no stamp, a temporary
#     file) and a stale stamp, checks the merge fails naming the missing frame,
#     resubmits the whole array and checks only those frames were rendered;
#  3. submits one task alone (--array 1) with hprt behind a wrapper that
#     holds back its JSON lines after the first, cancels it with scancel
#     mid-chunk, checks what it left (one stamped frame, no temporary files,
#     no processes), resubmits the whole array and checks only the unstamped
#     frames were rendered;
#  4. resubmits once more with nothing left to do;
#  5. checks bad parameters are refused with exit code 2.
# Needs root and the Debian packages slurm-wlm and munge (scripts/setup.sh);
# without them it says so and fails. The daemons are stopped and the
# directory removed on exit, also on failure. Prints "N passed, M failed".
set -euo pipefail

hprt_arg="${1:-}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cluster="$root/scripts/cluster"
scene_src="$root/data/scenes/anim_wave.json"
wait_s="${HPRT_SLURM_TEST_TIMEOUT:-120}"
opts=(--width 96 --height 72 --threads 1)
passed=0 failed=0 summary_printed=0
T0=$SECONDS

say() { echo "test_slurm_array: $*" >&2; }
not_run() {
  say "NOT RUN, counted as a failure: $*"
  echo "0 passed, 1 failed"
  exit 1
}
ok() { passed=$((passed + 1)); echo "  ok   $*"; }
bad() { failed=$((failed + 1)); echo "  FAIL $*"; }
check() {  # description command...
  local d="$1"
  shift
  if "$@"; then ok "$d"; else bad "$d"; fi
}
fatal() {  # stops the test: logs are dumped by the exit trap
  bad "$*"
  exit 1
}

# ---- prerequisites ---------------------------------------------------------
[ -n "$hprt_arg" ] || not_run "usage: test_slurm_array.sh /path/to/hprt"
[ -x "$hprt_arg" ] && [ -f "$hprt_arg" ] || not_run "hprt binary '$hprt_arg' is not an executable file"
hprt="$(realpath "$hprt_arg")"
[ "$(id -u)" -eq 0 ] || not_run "needs root (it starts munged, slurmctld and slurmd)"
for c in munged munge unmunge slurmctld slurmd sbatch squeue scontrol sinfo scancel sha256sum cmp; do
  command -v "$c" >/dev/null || not_run "'$c' not found: install the packages slurm-wlm and munge (scripts/setup.sh)"
done
[ -x /usr/bin/python3 ] || not_run "/usr/bin/python3 not found (merge-frames.sh needs it)"
[ -f "$scene_src" ] || not_run "scene $scene_src not found"

# Nothing from an enclosing Slurm job or the site's configuration.
while IFS= read -r v; do unset "$v"; done < <(compgen -e | grep -E '^(SLURM_|SBATCH_|SQUEUE_|SINFO_|SCONTROL_|SRUN_|HPRT_)' || true)

D="$(mktemp -d /tmp/hprt-slurm-test.XXXXXX)"
chmod 755 "$D"  # munged wants its socket directory reachable by all
mkdir -m 700 "$D/munge"
mkdir -m 755 "$D/run" "$D/log"
mkdir -p "$D/state" "$D/spool" "$D/work"
export SLURM_CONF="$D/slurm.conf"
munged_pid="" ctld_pid="" slurmd_pid=""

dump_logs() {
  say "---- diagnostics ($D)"
  local f
  for f in "$D"/log/*.log "$D"/log/*.out; do
    [ -f "$f" ] || continue
    echo "---- $f (last 40 lines)" >&2
    tail -n 40 "$f" >&2
  done
  for f in "$D"/work/*/logs/*.log; do
    [ -f "$f" ] || continue
    echo "---- task log $f" >&2
    tail -n 20 "$f" >&2
  done
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    echo "---- squeue / sinfo" >&2
    timeout 5 squeue -a >&2 || true
    timeout 5 sinfo -N -l >&2 || true
  fi
}
stop_pid() {  # pid name: TERM, up to 10 s, then KILL
  local pid="$1" i
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < 100; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    say "$2 (pid $pid) did not stop on TERM: killing it"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  wait "$pid" 2>/dev/null || true
}
cleanup() {
  local rc=$?
  set +e
  trap - EXIT INT TERM
  if [ "$rc" -ne 0 ] || [ "$failed" -ne 0 ]; then
    dump_logs
    [ "$rc" -ne 0 ] || rc=1
  fi
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    timeout 5 scancel --quiet --full --user=root 2>/dev/null
    local i
    for ((i = 0; i < 50; i++)); do
      [ -z "$(timeout 5 squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
  stop_pid "$slurmd_pid" slurmd
  stop_pid "$ctld_pid" slurmctld
  stop_pid "$munged_pid" munged
  # Job steps (slurmstepd, hprt) outlive slurmd: find ours by their
  # SLURM_CONF, which points into this test's directory.
  local p
  for p in /proc/[0-9]*; do
    p="${p#/proc/}"
    [ "$p" != $$ ] || continue
    if tr '\0' '\n' 2>/dev/null <"/proc/$p/environ" | grep -qxF "SLURM_CONF=$D/slurm.conf"; then
      say "killing leftover job process $p ($(tr '\0' ' ' 2>/dev/null <"/proc/$p/cmdline" | cut -c1-60))"
      kill -KILL "$p" 2>/dev/null
    fi
  done
  rm -rf "$D"
  [ "$summary_printed" == 1 ] || echo "$passed passed, $failed failed"
  exit "$rc"
}
trap cleanup EXIT
trap 'bad "interrupted (SIGINT)"; exit 130' INT
trap 'bad "interrupted (SIGTERM)"; exit 143' TERM

poll() {  # seconds command...: until the command succeeds
  local deadline=$((SECONDS + $1))
  shift
  until "$@"; do
    ((SECONDS < deadline)) || return 1
    sleep 0.2
  done
}

# ---- the cluster -------------------------------------------------------------
say "starting munged, slurmctld, slurmd in $D"
dd if=/dev/urandom of="$D/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$D/munge/munge.key"
sock="$D/run/munge.sock"
munged --foreground --key-file="$D/munge/munge.key" --socket="$sock" \
  --pid-file="$D/run/munged.pid" --log-file="$D/log/munged.log" \
  --seed-file="$D/munge/munged.seed" >"$D/log/munged.out" 2>&1 &
munged_pid=$!
munge_ok() { munge -n -S "$sock" 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1; }
poll 15 munge_ok || fatal "munged did not start (credential round trip through $sock failed)"

read -r ctld_port slurmd_port < <(/usr/bin/python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
host="$(hostname -s 2>/dev/null || uname -n)"
host="${host%%.*}"
node="hprt-node1"
cpus="$(nproc)"
cat >"$SLURM_CONF" <<EOF
# Generated by tests/cluster/test_slurm_array.sh: a one-node test cluster.
ClusterName=hprttest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
CommunicationParameters=NoInAddrAny,NoCtldInAddrAny
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/run/slurmctld.pid
SlurmdPidFile=$D/run/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SchedulerParameters=sched_interval=1,sched_min_interval=0
MinJobAge=600
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 NodeHostname=$host CPUs=$cpus RealMemory=256 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -f "$SLURM_CONF" >"$D/log/slurmctld.out" 2>&1 &
ctld_pid=$!
ctld_up() { kill -0 "$ctld_pid" 2>/dev/null && timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP'; }
poll 30 ctld_up || fatal "slurmctld did not come up on 127.0.0.1:$ctld_port"
slurmd -D -f "$SLURM_CONF" -N "$node" >"$D/log/slurmd.out" 2>&1 &
slurmd_pid=$!
node_idle() {
  kill -0 "$slurmd_pid" 2>/dev/null &&
    [ "$(timeout 5 sinfo -h -n "$node" -o %t 2>/dev/null)" == idle ]
}
poll 30 node_idle || fatal "node $node did not become idle (slurmd on 127.0.0.1:$slurmd_port)"
ok "one-node Slurm cluster up: $node, $cpus CPUs, slurmctld 127.0.0.1:$ctld_port, slurmd 127.0.0.1:$slurmd_port ($((SECONDS - T0)) s)"

# ---- helpers -----------------------------------------------------------------
scene="$D/work/anim_wave.json"
cp "$scene_src" "$scene"
out="$D/work/frames"
ref="$D/work/ref"
frame() { printf '%s/frame_%04d.png' "$1" "$2"; }
export HPRT_BIN="$hprt"

submit() {  # [--array SPEC]: prints the job id
  "$cluster/submit.sh" "$@" "$scene" 0:8 3 "$out" "${opts[@]}"
}
job_gone() { [ -z "$(timeout 5 squeue -h -j "$1" -o %i 2>/dev/null)" ] && ctld_up; }
wait_job() {  # job expected_tasks: waits, then checks every task COMPLETED with exit 0
  local job="$1" n="$2" start=$SECONDS
  poll "$wait_s" job_gone "$job" || fatal "job $job still queued or running after $wait_s s"
  local states
  states="$(scontrol -o show job "$job" | sed -n 's/.*ArrayTaskId=\([0-9]*\) .*JobState=\([A-Z_]*\) .* ExitCode=\([0-9:]*\).*/\1 \2 \3/p' | sort -n)" || true
  local want="" i
  for ((i = 0; i < n; i++)); do want+="${want:+$'\n'}$i COMPLETED 0:0"; done
  if [ "$states" == "$want" ]; then
    ok "job $job: $n task(s) COMPLETED, exit 0 ($((SECONDS - start)) s)"
  else
    fatal "job $job task states: $(tr '\n' ';' <<<"$states") (want $n COMPLETED 0:0)"
  fi
}
record_frames() {  # job: the frames in that job's task records, sorted, one line
  cat "$out"/records/task_"$1"_*.jsonl 2>/dev/null |
    sed -n 's/.*"frame":\([0-9]*\)[,}].*/\1/p' | sort -n | tr '\n' ' ' | sed 's/ $//'
}
record_frames_of_task() {  # job task
  sed -n 's/.*"frame":\([0-9]*\)[,}].*/\1/p' "$out/records/task_$1_$2.jsonl" 2>/dev/null | sort -n | tr '\n' ' ' | sed 's/ $//'
}
same_as_ref() {  # frames...: byte-identical to the reference run
  local k
  for k in "$@"; do cmp -s "$(frame "$out" "$k")" "$(frame "$ref" "$k")" || { echo "  frame $k differs" >&2; return 1; }; done
}
identity() {  # inode and mtime of each frame image
  local k
  for k in 0 1 2 3 4 5 6 7; do stat -c "$k %i %y" "$(frame "$out" "$k")" 2>/dev/null || echo "$k absent"; done
}
no_temp_files() { [ -z "$(find "$out" -name '*.tmp*' -o -name '.task_*' | head -1)" ]; }
plan_missing() {  # render options...: frames the tasks would render now
  HPRT_PLAN=1 bash "$cluster/render-array.sbatch" "$scene" 0:8 3 "$out" "$@" | sed -n 's/^missing=//p'
}

# ---- 1. the whole array -----------------------------------------------------------
say "reference: one hprt render --frames 0:8 run"
mkdir -p "$ref"
start=$SECONDS
"$hprt" render "$scene" --frames 0:8 -o "$ref/frame_%04d.png" --json "${opts[@]}" >"$ref/frames.jsonl" 2>"$ref/stderr.log" ||
  fatal "reference render failed: $(tail -n 3 "$ref/stderr.log")"
check "reference run wrote 8 frames and 8 JSON lines ($((SECONDS - start)) s)" \
  test "$(ls "$ref"/frame_*.png | wc -l)" -eq 8 -a "$(wc -l <"$ref/frames.jsonl")" -eq 8

say "submitting frames 0:8 in chunks of 3"
job1="$(submit)" || fatal "submit.sh failed"
check "submit.sh printed a job id ($job1)" test -n "$job1" -a -z "${job1//[0-9]/}"
wait_job "$job1" 3
check "all 8 frames byte-identical to the single --frames 0:8 run" same_as_ref 0 1 2 3 4 5 6 7
stamps_ok() {
  local k want
  want="$(printf 'scene_sha256 %s\noptions %s' "$(sha256sum <"$scene" | cut -d' ' -f1)" "${opts[*]}")"
  for k in 0 1 2 3 4 5 6 7; do [ "$(cat "$(frame "$out" "$k").stamp" 2>/dev/null)" == "$want" ] || return 1; done
}
check "every frame has a stamp with the scene's sha256 and the options" stamps_ok
check "task 0 recorded frames 0 1 2" test "$(record_frames_of_task "$job1" 0)" == "0 1 2"
check "task 1 recorded frames 3 4 5" test "$(record_frames_of_task "$job1" 1)" == "3 4 5"
check "task 2 recorded frames 6 7" test "$(record_frames_of_task "$job1" 2)" == "6 7"
check "one task log per task" test "$(ls "$out"/logs/*_"$job1"_*.log | wc -l)" -eq 3
check "no temporary files left" no_temp_files
merge_out="$("$cluster/merge-frames.sh" "$out" 0:8 --jsonl "$D/work/merged.jsonl" 2>&1)" && merge_rc=0 || merge_rc=$?
echo "$merge_out" | sed 's/^/    /'
check "merge-frames.sh succeeds" test "$merge_rc" -eq 0
check "merged table: 8 frame rows, totals line" \
  test "$(grep -cE '^ +[0-7] ' <<<"$merge_out")" -eq 8 -a "$(grep -c '^total: 8 of 8 frames' <<<"$merge_out")" -eq 1
check "merged JSON lines: frames 0..7" \
  test "$(sed -n 's/.*"frame": \([0-9]*\),.*/\1/p' "$D/work/merged.jsonl" | tr '\n' ' ')" == "0 1 2 3 4 5 6 7 "
check "the first frame of each task is a full build, the others updates" \
  test "$(sed -n 's/.*"frame": \([0-9]*\),.*"rebuilt": true.*/\1/p' "$D/work/merged.jsonl" | tr '\n' ' ')" == "0 3 6 "

# ---- 2. damage, then resubmit the whole array -------------------------------------
before="$(identity)"
rm -f "$(frame "$out" 4)"                               # a lost frame
rm -f "$(frame "$out" 7).stamp"                         # a task killed after the rename,
echo partial >"$(frame "$out" 7).tmp-99999-1"           # before its stamp, and mid-write
sed -i 's/^scene_sha256 .*/scene_sha256 0000/' "$(frame "$out" 1).stamp"  # a stale stamp
merge_out="$("$cluster/merge-frames.sh" "$out" 0:8 2>&1)" && merge_rc=0 || merge_rc=$?
check "merge-frames.sh fails (exit 1) naming missing frame 4" \
  test "$merge_rc" -eq 1 -a "$(grep -c 'missing frames: 4$' <<<"$merge_out")" -eq 1
check "plan: frames 1 4 7 to render" test "$(plan_missing "${opts[@]}")" == "1 4 7"
check "plan with other render options: all 8 frames to render" \
  test "$(plan_missing --width 64 --height 48 --threads 1)" == "0 1 2 3 4 5 6 7"

say "resubmitting the whole array"
job2="$(submit)" || fatal "submit.sh failed"
wait_job "$job2" 3
check "resubmission rendered only frames 1 4 7" test "$(record_frames "$job2")" == "1 4 7"
after="$(identity)"
untouched() { diff <(grep -vE '^[147] ' <<<"$before") <(grep -vE '^[147] ' <<<"$after") >&2; }
check "frames 0 2 3 5 6 untouched (same inode and mtime)" untouched
check "frames 1 4 7 replaced" test "$(diff <(echo "$before") <(echo "$after") | grep -c '^>')" -eq 3
check "all 8 frames byte-identical to the reference again" same_as_ref 0 1 2 3 4 5 6 7
check "stamps complete again" stamps_ok
check "the killed task's temporary file is gone" no_temp_files
merge_out="$("$cluster/merge-frames.sh" "$out" 0:8 --jsonl "$D/work/merged.jsonl" 2>&1)" && merge_rc=0 || merge_rc=$?
check "merge-frames.sh succeeds again" test "$merge_rc" -eq 0
check "merged records of frames 1 4 7 come from the resubmission" \
  test "$(grep -c "\"job\": \"${job2}_" "$D/work/merged.jsonl")" -eq 3

# ---- 3. one task alone, cancelled mid-chunk by scancel; resubmitted -------------
# hprt behind a wrapper that lets only the first frame's JSON line through and
# then waits: the task is cancelled after frame 3 was reported and stamped,
# with frames 4 5 rendered or still rendering but not reported.
rm -f "$out"/frame_000[345].png "$out"/frame_000[345].png.stamp
held="$D/work/hprt-held"
cat >"$held" <<EOF
#!/bin/bash
echo \$\$ >>"$D/work/held.pids"
"$hprt" "\$@" | { IFS= read -r line && printf '%s\\n' "\$line"; sleep 300 & echo \$! >>"$D/work/held.pids"; wait; cat; }
EOF
chmod +x "$held"
job3="$(HPRT_BIN="$held" submit --array 1)" || fatal "submit.sh --array 1 failed"
poll "$wait_s" test -f "$(frame "$out" 3).stamp" || fatal "job $job3 did not stamp frame 3 within $wait_s s"
scancel "$job3"
poll "$wait_s" job_gone "$job3" || fatal "job $job3 still there $wait_s s after scancel"
check "task 1 alone (--array 1), cancelled mid-chunk: CANCELLED" \
  test "$(scontrol -o show job "$job3" | grep -c 'ArrayTaskId=1 .*JobState=CANCELLED')" -eq 1 -a "$(scontrol -o show job "$job3" | wc -l)" -eq 1
check "the cancelled task recorded frame 3 only" test "$(record_frames "$job3")" == "3"
check "frame 3 stamped, frames 4 5 not" \
  test -f "$(frame "$out" 3).stamp" -a ! -e "$(frame "$out" 4).stamp" -a ! -e "$(frame "$out" 5).stamp"
held_gone() {  # the wrapper and its sleep
  local p
  for p in $(cat "$D/work/held.pids"); do ! kill -0 "$p" 2>/dev/null || return 1; done
}
check "Slurm ended the task's processes" poll 10 held_gone
check "no partial images or temporary files" no_temp_files
job3b="$(submit)" || fatal "submit.sh failed"
wait_job "$job3b" 3
check "the resubmission rendered only frames 4 5" test "$(record_frames "$job3b")" == "4 5"
check "frames 3 4 5 byte-identical to the reference" same_as_ref 3 4 5

# ---- 4. a resubmission with nothing to do -----------------------------------------
before="$(identity)"
job4="$(submit)" || fatal "submit.sh failed"
wait_job "$job4" 3
check "a resubmission with every frame done renders nothing" \
  test -z "$(record_frames "$job4")" -a "$(ls "$out"/records/task_"$job4"_*.jsonl | wc -l)" -eq 3
check "and touches no frame" test "$(identity)" == "$before"
check "merge-frames.sh succeeds at the end" "$cluster/merge-frames.sh" "$out" 0:8 >/dev/null 2>&1

# ---- 5. bad parameters: exit 2, one line, nothing submitted -------------------------------
refused() {  # command...: exit 2 with exactly one line on stderr
  local err rc=0
  err="$("$@" 2>&1 >/dev/null)" || rc=$?
  [ "$rc" -eq 2 ] && [ "$(wc -l <<<"$err")" -eq 1 ] || { echo "  rc=$rc: $err" >&2; return 1; }
}
njobs="$(scontrol -o show job | grep -c JobId=)" || true
check "submit.sh refuses a missing scene" refused "$cluster/submit.sh" "$D/none.json" 0:8 3 "$out"
check "submit.sh refuses range 5:3" refused "$cluster/submit.sh" "$scene" 5:3 3 "$out"
check "submit.sh refuses range 0:99 (past the animation's 48 frames)" refused "$cluster/submit.sh" "$scene" 0:99 3 "$out"
check "submit.sh refuses chunk 0" refused "$cluster/submit.sh" "$scene" 0:8 0 "$out"
check "submit.sh refuses --frames among the render options" refused "$cluster/submit.sh" "$scene" 0:8 3 "$out" --frames 0:2
check "render-array.sbatch refuses chunk x" refused bash "$cluster/render-array.sbatch" "$scene" 0:8 x "$out"
check "render-array.sbatch refuses task 3 of 3" refused env HPRT_TASK=3 bash "$cluster/render-array.sbatch" "$scene" 0:8 3 "$out"
check "nothing was submitted by them" test "$(scontrol -o show job | grep -c JobId=)" -eq "$njobs"

echo "test_slurm_array: $((SECONDS - T0)) s" >&2
echo "$passed passed, $failed failed"
summary_printed=1
[ "$failed" -eq 0 ]
