#!/usr/bin/env bash
# livo-vio-feature in the pipeline (issue 14), on 12 s of the bridge deck (wheels, an RGB-D camera,
# a VLP-16):
#  (a) alone, its odometry on ODOMETRY (overlay): odometry.tum, work:image in timing.json, ATE under
#      0.5 % of the distance (measured: 0.050 m over 36.3 m, 0.14 %), one VISUAL_STATE per image that
#      gave a state (230 of 240: the first half second initialises);
#  (b) two lockstep runs give identical ODOMETRY and VISUAL_STATE;
#  (c) coupled with livo-lio-graph (REGISTERED_SCAN gives LiDAR depth): both estimates, images with
#      LiDAR depth in the VIO's log;
#  (d) playback faults on its inputs: no NaN in VISUAL_STATE, still an estimate at the end, ATE
#      under 1 % (measured 0.063 m, 0.17 %);
#  (e) a dead camera (and depth) for 2 s: no state meanwhile, states again at once after (ATE under
#      1 %; measured 0.058 m).
# About 50 s on the 2-core development machine.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-vio-feature-pipeline.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
config="$root/config/sim/bridge_deck.yaml"
"$bin/livo-sim" --config "$config" --out "$dir/bridge.lcmlog" --duration 12 --seed 2 --quiet >/dev/null 2>"$dir/sim.err" \
  || { cat "$dir/sim.err"; fail "livo-sim failed"; }
cat > "$dir/vio_only.yaml" <<'YAML'
vio_feature: {channels: {odometry: ODOMETRY}, lidar_depth: false}
YAML
# vio_only RUN [run_pipeline.sh options...]
vio_only() {
  local run="$1"; shift
  "$root/scripts/run_pipeline.sh" --log "$dir/bridge.lcmlog" --config "$config" --processes vio_feature \
    --overlay "$dir/vio_only.yaml" --record ODOMETRY,VISUAL_STATE,HEALTH,GROUND_TRUTH --out "$dir/$run" "$@" \
    >/dev/null 2>"$dir/$run.err" || { cat "$dir/$run.err"; fail "run $run failed"; }
}
# check RUN ATE_BAR_PERCENT MIN_STATES: the outputs, the ATE against the distance, VISUAL_STATE
# finite and one per image with a state, an estimate within 1 s of the end
check() {
  "$bin/livo-loginfo" --nonfinite "$dir/$1/outputs.lcmlog" >"$dir/$1.loginfo" 2>&1 \
    || { cat "$dir/$1.loginfo"; fail "$1: NaN or infinity in the outputs"; }
  /usr/bin/python3 - "$dir/$1" "$2" "$3" "$dir/$1.loginfo" <<'PY' || exit 1
import json, math, re, sys
d, bar_percent, min_states, loginfo = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
rows = [[float(x) for x in l.split()] for l in open(d + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert len(rows) >= min_states and all(len(r) == 8 for r in rows), len(rows)
t = json.load(open(d + '/timing.json'))
v = t['vio_feature']['channels']
images = v['work:image']['messages']
summary = [l for l in open(d + '/logs/vio_feature.log') if re.search(r'\] \d+ images: \d+ with a state', l)]
assert summary, 'no summary in logs/vio_feature.log'
processed, with_state = map(int, re.search(r'(\d+) images: (\d+) with a state', summary[-1]).groups())
assert processed == images, (processed, images)
counts = {l.split()[0]: int(l.split()[2]) for l in open(loginfo) if l.split() and l.split()[0].isupper() and len(l.split()) > 2 and l.split()[2].isdigit()}
assert counts.get('VISUAL_STATE') == with_state == len(rows), (counts.get('VISUAL_STATE'), with_state, len(rows))
end = float(open(d + '/../log_end.txt').read())
assert rows[-1][0] > end - 1.0, 'no estimate in the last second (%.2f s before the end)' % (end - rows[-1][0])
e = json.load(open(d + '/evaluation_odometry.json'))
dist = e['end_point']['path_length_m']
ate = e['ate']['rmse']
print('%s: %d of %d images with a state, %.1f m, ATE rmse %.3f m (%.2f %%, bar %.1f %%), median %.1f ms per image, peak RSS %.0f MB'
      % (d.split('/')[-1], with_state, processed, dist, ate, 100 * ate / dist, bar_percent, v['work:image']['median_ms'],
         t['vio_feature']['peak_rss_mb']))
assert ate < bar_percent / 100 * dist, 'ATE %.3f m over %.1f m' % (ate, dist)
PY
}

"$bin/livo-loginfo" "$dir/bridge.lcmlog" | sed -n 's/^end: *\([0-9.]*\) s$/\1/p' > "$dir/log_end.txt"
"$bin/livo-loginfo" "$dir/bridge.lcmlog" | sed -n 's/^start: *\([0-9.]*\) s$/\1/p' > "$dir/log_start.txt"
[ -s "$dir/log_end.txt" ] && [ -s "$dir/log_start.txt" ] || fail "livo-loginfo gave no start or end time"

# (a) alone, (b) twice
vio_only a
check a 0.5 150
vio_only b
# channel, message count and payload digest (the rate column follows the recording's wall clock)
digests() { "$bin/livo-loginfo" --digest "$dir/$1/outputs.lcmlog" | awk '{print $1, $3, $NF}'; }
digests a > "$dir/a.digest" && digests b > "$dir/b.digest" || fail "livo-loginfo failed"
for ch in ODOMETRY VISUAL_STATE; do
  a=$(grep "^$ch " "$dir/a.digest"); b=$(grep "^$ch " "$dir/b.digest")
  [ -n "$a" ] || fail "no $ch in the outputs"
  [ "$a" = "$b" ] || fail "two lockstep runs gave different $ch ($a vs $b)"
done
echo "two runs: identical ODOMETRY and VISUAL_STATE"

# (c) coupled: livo-lio-graph's REGISTERED_SCAN gives the VIO LiDAR depth
"$root/scripts/run_pipeline.sh" --log "$dir/bridge.lcmlog" --config "$config" --processes lio,vio_feature \
  --swap lio="$bin/livo-lio-graph" --record ODOMETRY,VISUAL_STATE,VISUAL_ODOMETRY,HEALTH,GROUND_TRUTH \
  --out "$dir/coupled" >/dev/null 2>"$dir/coupled.err" || { cat "$dir/coupled.err"; fail "the coupled run failed"; }
"$bin/livo-loginfo" --nonfinite "$dir/coupled/outputs.lcmlog" >"$dir/coupled.loginfo" 2>&1 \
  || { cat "$dir/coupled.loginfo"; fail "coupled: NaN or infinity in the outputs"; }
/usr/bin/python3 - "$dir/coupled" "$dir/coupled.loginfo" <<'PY' || exit 1
import json, re, sys
d, loginfo = sys.argv[1], sys.argv[2]
counts = {l.split()[0]: int(l.split()[2]) for l in open(loginfo) if len(l.split()) > 2 and l.split()[2].isdigit()}
assert counts.get('ODOMETRY', 0) >= 100 and counts.get('VISUAL_ODOMETRY', 0) >= 150, counts
m = re.findall(r'(\d+) images: (\d+) with a state.*?, (\d+) with LiDAR depth', open(d + '/logs/vio_feature.log').read())
assert m, 'no LiDAR depth in the summary of logs/vio_feature.log'
images, with_state, lidar = map(int, m[-1])
assert lidar >= 0.8 * with_state, (images, with_state, lidar)
e = json.load(open(d + '/evaluation_odometry.json'))
t = json.load(open(d + '/timing.json'))
print('coupled: lio %d poses (ATE rmse %.3f m), vio %d of %d images with a state, %d with LiDAR depth, %.1f ms per image'
      % (counts['ODOMETRY'], e['ate']['rmse'], with_state, images, lidar, t['vio_feature']['channels']['work:image']['median_ms']))
PY

# (d) faults on every input of the VIO
vio_only faults --seed 5 \
  --faults "drop:IMU:0.05,duplicate:IMU:0.05,reorder:IMU:0.05,drop:CAMERA:0.05,corrupt:CAMERA:0.05,corrupt:DEPTH:0.05,delay:DEPTH:0.1:0.2,drop:WHEEL:0.1,reorder:WHEEL:0.05"
check faults 1.0 120

# (e) a dead camera (and its depth) from 6 to 8 s
vio_only dead_camera --faults "cut:CAMERA:6:8,cut:DEPTH:6:8"
check dead_camera 1.0 110
/usr/bin/python3 - "$dir/dead_camera" "$(cat "$dir/log_start.txt")" <<'PY' || exit 1
import re, sys
d, start = sys.argv[1], float(sys.argv[2])
t = [float(l.split()[0]) - start for l in open(d + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert not any(6.05 < x < 7.95 for x in t), 'states while the camera was dead'
after = [x for x in t if x >= 7.95]
assert after and after[0] < 8.5, 'no state in the 0.5 s after the camera came back'
restarts = re.findall(r'; (\d+) restarts', open(d + '/logs/vio_feature.log').read())
print('dead camera 6-8 s: first state again at %.2f s, %s restarts' % (after[0], restarts[-1] if restarts else 0))
PY

# (f) the coupling table end to end on 4 s (too short for its bars: only the table is checked)
/usr/bin/python3 "$root/scripts/visual_coupling_table.py" --out "$dir/coupling" --configs bridge_deck --seeds 1 \
  --duration 4 >"$dir/coupling.txt" 2>&1
rc=$?
[ $rc -le 1 ] || { cat "$dir/coupling.txt"; fail "visual_coupling_table.py failed ($rc)"; }
echo "coupling table:"
/usr/bin/python3 "$root/tests/pipeline/check_variant_table.py" "$dir/coupling/table.md" bridge_deck 1 3 ||
  { cat "$dir/coupling.txt"; fail "the coupling table is not what it should be"; }
