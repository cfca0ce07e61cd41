#!/usr/bin/env bash
# Supervised runs (scripts/run_pipeline.sh --respawn) of the whole pipeline on a simulated room:
# each process in turn is stopped mid-run with SIGTERM and, once restarted, killed with SIGKILL.
# Every run must finish, report.md must list both restarts, no recorded output may hold a NaN, the
# online odometry may have no gap longer than MAX_GAP_S of log time, and (except when the LIO
# itself restarts, which begins a new odometry frame) the accuracy stays near the clean run's.
#   supervision_test.sh ROOT BIN [PROCESS...]
set -uo pipefail
root="$1"; bin="$2"; shift 2
processes=("$@"); [ ${#processes[@]} -gt 0 ] || processes=(lio vio loop colour octomap)
dir=$(mktemp -d /tmp/livo-supervision.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
config="$root/config/sim/room.yaml"
MAX_GAP_S=1.5   # log seconds without odometry: the restart itself is held by lockstep; a new LIO
                # needs about a second of IMU and two sweeps to initialise
ATE_MARGIN_M=0.01

"$bin/livo-sim" --config "$config" --out "$dir/room.lcmlog" --duration 20 --seed 11 --quiet || fail "livo-sim failed"
"$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$config" --out "$dir/clean" >/dev/null 2>"$dir/clean.err" \
  || { cat "$dir/clean.err"; fail "the clean run failed"; }

for p in "${processes[@]}"; do
  out="$dir/$p"
  "$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$config" --out "$out" --respawn \
    --kill "$p:TERM:6,$p:KILL:13" >/dev/null 2>"$out.err" || { cat "$out.err"; fail "$p: the supervised run failed"; }
  "$bin/livo-loginfo" --nonfinite "$out/outputs.lcmlog" >"$out.loginfo" 2>&1 || { cat "$out.loginfo"; fail "$p: NaN in the outputs"; }
  /usr/bin/python3 - "$dir/clean" "$out" "$p" "$MAX_GAP_S" "$ATE_MARGIN_M" <<'PY' || exit 1
import json, math, re, sys
clean, out, p, max_gap, margin = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
report = open(out + '/report.md').read()
section = report.split('## Restarts', 1)[1].split('\n## ', 1)[0] if '## Restarts' in report else ''
rows = [l for l in section.splitlines() if l.startswith('| ' + p + ' |')]
assert len(rows) == 2, f'{p}: expected two restarts in report.md, got:\n{section}'
assert 'SIGTERM' in rows[0] or 'exited with code' in rows[0], rows[0]
assert 'SIGKILL' in rows[1], rows[1]
odo = [[float(x) for x in l.split()] for l in open(out + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert all(math.isfinite(v) for r in odo for v in r), f'{p}: NaN in odometry.tum'
ref = [[float(x) for x in l.split()] for l in open(clean + '/odometry.tum') if l.strip() and not l.startswith('#')]
gap = max(b[0] - a[0] for a, b in zip(odo, odo[1:]))
assert len(odo) >= len(ref) - max_gap * 10 - 5, f'{p}: {len(odo)} poses against {len(ref)} in the clean run'
assert gap <= max_gap, f'{p}: the odometry has a gap of {gap:.2f} s (bar {max_gap} s)'
ate = json.load(open(out + '/evaluation_odometry.json'))['ate']['rmse']
ref_ate = json.load(open(clean + '/evaluation_odometry.json'))['ate']['rmse']
if p != 'lio':
    assert ate <= ref_ate + margin, f'{p}: ATE {ate:.4f} m against {ref_ate:.4f} m clean (margin {margin} m)'
else:
    # each restart goes on in a new odometry epoch, with keyframe ids that never repeat
    assert '| odometry resets | 2 ' in report, f'{p}: expected two odometry resets in report.md'
    timing = json.load(open(out + '/timing.json'))
    rejected = timing.get('loop', {}).get('channels', {}).get('KEYFRAME', {}).get('rejected', 0)
    assert rejected == 0, f'{p}: loop refused {rejected} keyframes after the restarts'
print(f'{p}: 2 restarts, {len(odo)} poses (clean {len(ref)}), longest gap {gap:.2f} s, ATE {ate:.4f} m (clean {ref_ate:.4f})')
PY
done
