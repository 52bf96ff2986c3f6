#!/usr/bin/env bash
# Merges the per-task JSON lines of a render-array job (OUT/records/*.jsonl,
# written by scripts/cluster/render-array.sbatch) into one table of frames
# A..B-1, sorted by frame, with totals:
#
#   merge-frames.sh OUT A:B [--jsonl FILE]
#
# A frame rendered more than once (a resubmission after its image was lost)
# counts with its latest record. Exits 1 naming the missing frames if any
# frame of A..B-1 has no record or no image; 2 on bad arguments. --jsonl also
# writes the merged records, one JSON line per frame, to FILE.
set -euo pipefail
die2() { echo "merge-frames: $*" >&2; exit 2; }
[ $# -eq 2 ] || [ $# -eq 4 ] || die2 "usage: merge-frames.sh OUT A:B [--jsonl FILE]"
out="$1" frames="$2" jsonl=""
if [ $# -eq 4 ]; then
  [ "$3" == --jsonl ] || die2 "unknown option '$3'"
  jsonl="$4"
fi
[ -d "$out" ] || die2 "'$out' is not a directory"
[[ "$frames" =~ ^[0-9]{1,9}:[0-9]{1,9}$ ]] || die2 "frames '$frames' is not A:B"
[ -x /usr/bin/python3 ] || die2 "needs /usr/bin/python3"

exec /usr/bin/python3 - "$out" "$frames" "$jsonl" <<'EOF'
import glob, json, os, sys

out, frames, jsonl = sys.argv[1], sys.argv[2], sys.argv[3]
first, end = (int(x) for x in frames.split(":"))
if first >= end:
    print(f"merge-frames: empty frame range '{frames}'", file=sys.stderr)
    sys.exit(2)

latest = {}  # frame -> record with the largest recorded_ns
files = sorted(glob.glob(os.path.join(out, "records", "task_*.jsonl")))
bad = 0
for path in files:
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                r = json.loads(line)
                k = int(r["frame"])
            except (ValueError, KeyError, TypeError):
                print(f"merge-frames: {path}:{n}: not a frame record", file=sys.stderr)
                bad += 1
                continue
            if k not in latest or r.get("recorded_ns", 0) >= latest[k].get("recorded_ns", 0):
                latest[k] = r

def image_path(r):  # the image beside the records, wherever the task saw OUT
    return os.path.join(out, os.path.basename(str(r.get("output", ""))))

no_record = [k for k in range(first, end) if k not in latest]
no_image = [k for k in range(first, end) if k in latest and not os.path.isfile(image_path(latest[k]))]

def fmt(v, spec):
    return format(v, spec) if isinstance(v, (int, float)) else "-"

rows = [latest[k] for k in range(first, end) if k in latest]
print(f"{'frame':>6} {'strategy':<16} {'rebuilt':>7} {'update ms':>10} {'render ms':>10} "
      f"{'Mrays/s':>8}  {'job':<12} output")
for r in rows:
    print(f"{r['frame']:>6} {str(r.get('strategy', '-')):<16} "
          f"{('yes' if r.get('rebuilt') else 'no'):>7} {fmt(r.get('update_ms'), '10.2f')} "
          f"{fmt(r.get('render_ms'), '10.2f')} {fmt(r.get('mrays_per_s'), '8.2f')}  "
          f"{str(r.get('job', '-')):<12} {r.get('output', '-')}")
update = sum(r.get("update_ms") or 0 for r in rows)
render = sum(r.get("render_ms") or 0 for r in rows)
rays = sum(r.get("rays") or 0 for r in rows)
rebuilds = sum(1 for r in rows if r.get("rebuilt"))
jobs = sorted({str(r.get("job", "-")) for r in rows})
mrays = rays / (render * 1e3) if render > 0 else 0.0
print(f"total: {len(rows)} of {end - first} frames ({frames}), {rebuilds} builds/rebuilds, "
      f"update {update:.2f} ms, render {render:.2f} ms, {mrays:.2f} Mrays/s, "
      f"{len(jobs)} task run(s), {len(files)} record file(s)")

if jsonl:
    tmp = f"{jsonl}.tmp.{os.getpid()}"
    with open(tmp, "w") as f:
        for r in rows:
            f.write(json.dumps(r, sort_keys=True) + "\n")
    os.replace(tmp, jsonl)

problems = []
if no_record:
    problems.append("no record for frame(s) " + " ".join(map(str, no_record)))
if no_image:
    problems.append("image missing for frame(s) " + " ".join(map(str, no_image)))
if bad:
    problems.append(f"{bad} unreadable record line(s)")
if problems:
    missing = sorted(set(no_record + no_image))
    print(f"merge-frames: FAILED: {'; '.join(problems)}; missing frames: "
          f"{' '.join(map(str, missing)) or 'none'}", file=sys.stderr)
    sys.exit(1)
print(f"merge-frames: all {end - first} frames of {frames} present", file=sys.stderr)
EOF
