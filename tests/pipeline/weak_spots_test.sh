#!/usr/bin/env bash
# A user's corridor run (config/sim/corridor.yaml with a 50 m LiDAR, 15 s) through the LIO: most sweeps are flagged
# degenerate, and report.md says where: its "Where the estimate was weak" section counts the
# degenerate sweeps as ODOMETRY has them, lists their stretches in seconds since the start (the
# longest first) and says the position was least certain along the direction of travel; the
# odometry figure marks them. run_pipeline.sh keeps the run on a private bus.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-weak-spots.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
"$root/tests/pipeline/axis_degenerate_corridor.sh" "$root" "$dir/corridor.yaml" || fail "no corridor config"
"$bin/livo-sim" --config "$dir/corridor.yaml" --out "$dir/corridor.lcmlog" --duration 15 --seed 2 --quiet \
  || fail "livo-sim failed"
"$root/scripts/run_pipeline.sh" --log "$dir/corridor.lcmlog" --config "$dir/corridor.yaml" \
  --processes lio --out "$dir/run" >/dev/null 2>"$dir/run.err" || { cat "$dir/run.err"; fail "the run failed"; }
/usr/bin/python3 -B - "$root" "$dir/run" <<'PY' || exit 1
import json, re, sys
root, d = sys.argv[1], sys.argv[2]
sys.path.insert(0, root + '/scripts')
import hard_table  # its ODOMETRY decoder counts the degenerate flags independently of livo-report

flagged, sweeps = hard_table.degenerate_sweeps(d + '/outputs.lcmlog')
assert sweeps > 100 and flagged > sweeps // 2, (flagged, sweeps)
report = open(d + '/report.md').read()
assert '## Where the estimate was weak' in report, report
section = report.split('## Where the estimate was weak')[1].split('\n## ')[0]
line = next(l for l in section.splitlines() if l.startswith('**Degenerate sweeps**'))
m = re.search(r': (\d+) of (\d+) \([0-9.]+ %\) in (\d+) stretch', line)
assert m, line
assert (int(m.group(1)), int(m.group(2))) == (flagged, sweeps), (line, flagged, sweeps)
assert 'along the direction of travel' in line, line
rows = [r for r in section.splitlines() if re.match(r'\| \d+\.\d \| \d+\.\d \| \d+ \| ', r)]
assert rows, section
spans = [(float(r.split('|')[1]), float(r.split('|')[2]), int(r.split('|')[3])) for r in rows]
assert all(0.0 <= a <= b <= 15.0 for a, b, _ in spans), spans
lengths = [b - a for a, b, _ in spans]
assert lengths == sorted(lengths, reverse=True), spans
assert len(rows) == min(10, int(m.group(3))), (rows, line)
w = json.load(open(d + '/weak_spots.json'))
assert w['degenerate']['count'] == flagged and sum(s['count'] for s in w['degenerate']['spans']) == flagged, w
svg = open(d + '/odometry.svg').read()
assert 'degenerate sweeps' in svg and 'stroke="#ff8c00"' in svg, 'the figure does not mark the degenerate sweeps'
print('corridor: %d of %d sweeps degenerate in %s stretches; the longest %.1f-%.1f s' % (flagged, sweeps, m.group(3), spans[0][0], spans[0][1]))
print(line)
PY
