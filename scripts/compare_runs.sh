#!/usr/bin/env bash
# Runs one log through several pipeline variants, one after the other in the same session, and
# writes a side-by-side table (accuracy, end-point drift, replay speed, per-process median time and
# peak memory) with each variant's ratio to the first. The pipeline benchmark of the README.
#
#   scripts/compare_runs.sh --log LOG --config FILE --out DIR \
#       --variant NAME="RUN_PIPELINE_ARGS" [--variant ...]
#
#   e.g. scripts/compare_runs.sh --log logs/corridor.lcmlog --config config/sim/corridor.yaml \
#          --out /tmp/cmp --variant livo="" --variant lio="--without vio"
#
# Writes DIR/NAME/ (each run_pipeline.sh output folder) and DIR/comparison.md (also printed).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

usage() { sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "compare_runs.sh: $*" >&2; exit 1; }

log="" config="" out=""
names=() args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --log) log="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --variant)
      [[ "$2" == *=* ]] || die "--variant wants NAME=\"ARGS\", got '$2'"
      names+=("${2%%=*}"); args+=("${2#*=}"); shift 2 ;;
    -h|--help) usage 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done
[ -n "$log" ] && [ -n "$config" ] && [ -n "$out" ] || usage
[ -f "$log" ] || die "no log '$log'"
[ "${#names[@]}" -ge 1 ] || die "give at least one --variant"
mkdir -p "$out"

for i in "${!names[@]}"; do
  name="${names[$i]}"
  echo "== variant $name: run_pipeline.sh ${args[$i]}" >&2
  rm -rf "${out:?}/$name"
  # shellcheck disable=SC2086  # the variant's arguments are meant to split
  "$root/scripts/run_pipeline.sh" --log "$log" --config "$config" --out "$out/$name" ${args[$i]} >/dev/null \
    || die "variant $name failed (see $out/$name/logs/)"
done

/usr/bin/python3 - "$out" "$log" "${names[@]}" <<'PY' | tee "$out/comparison.md"
import json, os, sys

out, log, names = sys.argv[1], sys.argv[2], sys.argv[3:]

def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None

def fmt(v, digits=4):
    return '-' if v is None else f'{v:.{digits}f}'

def ratio(v, base):
    return '' if v is None or not base else f' ({v / base:.2f}×)'

rows, processes = [], []
for name in names:
    d = os.path.join(out, name)
    odo = load(os.path.join(d, 'evaluation_odometry.json'))
    traj = load(os.path.join(d, 'evaluation_trajectory.json')) or odo
    timing = load(os.path.join(d, 'timing.json')) or {}
    try:
        log_s, wall_s = (float(x) for x in open(os.path.join(d, 'logs', 'replay_times.txt')).read().split()[:2])
    except (OSError, ValueError):
        log_s = wall_s = 0.0
    per = {}
    for proc, t in timing.items():
        if proc == 'record':
            continue
        work = {ch: c for ch, c in t.get('channels', {}).items() if ch.startswith('work:')}
        # the process's own unit of work if it records one, else its busiest input
        ch, c = max(work.items(), key=lambda kv: kv[1]['messages']) if work else \
            (t.get('busiest_channel'), t.get('channels', {}).get(t.get('busiest_channel'), {}))
        per[proc] = (ch, c.get('median_ms'), t.get('peak_rss_mb'))
        if proc not in processes:
            processes.append(proc)
    rows.append(dict(name=name,
                     ate_odo=odo['ate']['rmse'] if odo else None,
                     ate_traj=traj['ate']['rmse'] if traj else None,
                     end=traj['end_point']['translation_m'] if traj and 'end_point' in traj else None,
                     end_pct=traj['end_point']['percent'] if traj and 'end_point' in traj else None,
                     speed=log_s / wall_s if wall_s > 0 else None, per=per))

base = rows[0]
print(f'# Pipeline comparison: {os.path.basename(log)}\n')
print(f'Variants run one after the other on this machine; ratios against `{base["name"]}`.\n')
print('| variant | ATE odometry (m) | ATE final (m) | end-point drift (m, %) | replay speed (× real time) |')
print('| --- | --- | --- | --- | --- |')
for r in rows:
    print(f'| {r["name"]} | {fmt(r["ate_odo"])}{ratio(r["ate_odo"], base["ate_odo"])} '
          f'| {fmt(r["ate_traj"])}{ratio(r["ate_traj"], base["ate_traj"])} '
          f'| {fmt(r["end"])}, {fmt(r["end_pct"], 2)} % | {fmt(r["speed"], 2)} |')
print('\n| process | ' + ' | '.join(r['name'] for r in rows) + ' |')
print('| --- |' + ' --- |' * len(rows))
for p in processes:
    cells = []
    for r in rows:
        ch, med, rss = r['per'].get(p, (None, None, None))
        cells.append('-' if ch is None else f'{fmt(med, 2)} ms/{ch}, {fmt(rss, 0)} MB')
    print(f'| {p} | ' + ' | '.join(cells) + ' |')
PY
