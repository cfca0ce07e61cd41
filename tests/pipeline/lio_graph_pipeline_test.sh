#!/usr/bin/env bash
# livo-lio-graph swapped in for livo-lio (issue 13): the whole pipeline on a short simulated room
# run (vio, loop, colour, octomap unchanged) writes every output, stays under the 5 cm bar, and two
# lockstep runs give byte-identical ODOMETRY and KEYFRAME; with NaN points, corrupted and dropped
# messages, duplicated and reordered IMU samples and a dead LiDAR second it keeps going and never
# publishes NaN; scripts/planar_wheel_ablation.py writes its table on a few seconds of bridge_deck.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-lio-graph-pipeline.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
. "$(dirname "$0")/input_faults.sh"
export LIVO_BUILD_DIR="$(dirname "$bin")"
"$bin/livo-sim" --config "$root/config/sim/room.yaml" --out "$dir/room.lcmlog" --duration 10 --seed 3 --quiet \
  || fail "livo-sim failed"
for run in a b; do
  "$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$root/config/sim/room.yaml" \
    --swap lio="$bin/livo-lio-graph" --out "$dir/$run" >/dev/null 2>"$dir/$run.err" \
    || { cat "$dir/$run.err"; fail "run $run failed"; }
done
for f in outputs.lcmlog odometry.tum trajectory.tum timing.json report.md evaluation_odometry.json colour_map.ply \
         octomap.bt keyframes.tum global_map.ply; do
  [ -s "$dir/a/$f" ] || fail "missing output $f"
done
/usr/bin/python3 - "$dir/a" <<'PY' || exit 1
import json, sys
d = sys.argv[1]
rows = [l.split() for l in open(d + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert len(rows) >= 90 and all(len(r) == 8 for r in rows), len(rows)
t = json.load(open(d + '/timing.json'))
assert t['lio']['channels']['LIDAR']['messages'] == 100, t['lio']
for p in ('loop', 'colour', 'octomap'):
    assert p in t, 'no %s in timing.json' % p
e = json.load(open(d + '/evaluation_odometry.json'))
assert e['ate']['rmse'] < 0.05, e['ate']
print('room with livo-lio-graph: %d poses, ATE rmse %.4f m, median %.1f ms per sweep'
      % (len(rows), e['ate']['rmse'], t['lio']['channels']['work:sweep']['median_ms']))
PY
# channel, message count and payload digest (the rate column follows the recording's wall clock)
digests() { "$bin/livo-loginfo" --digest "$1/outputs.lcmlog" | awk '{print $1, $3, $NF}'; }
digests "$dir/a" > "$dir/a.digest" && digests "$dir/b" > "$dir/b.digest" || fail "livo-loginfo failed"
for ch in ODOMETRY KEYFRAME REGISTERED_SCAN COLORED_CLOUD OCTOMAP; do
  grep -q "^$ch" "$dir/a.digest" || fail "no $ch in the outputs"
done
for ch in ODOMETRY KEYFRAME; do
  a=$(grep "^$ch" "$dir/a.digest"); b=$(grep "^$ch" "$dir/b.digest")
  [ "$a" = "$b" ] || fail "two lockstep runs gave different $ch ($a vs $b)"
done
echo "two runs: identical ODOMETRY and KEYFRAME"

check_input_faults 70 --swap lio="$bin/livo-lio-graph"

# The ablation script end to end on 4 s (too short for its bars: the table, the honesty about
# variants left out and the keyed reuse are checked)
/usr/bin/python3 "$root/scripts/planar_wheel_ablation.py" --out "$dir/ablation" --configs bridge_deck --seeds 1 \
  --duration 4 --variants graph,graph-bare,lio >"$dir/ablation.txt" 2>&1
rc=$?
# three of the six variants: the bars that need the others are missed, not passed
[ $rc -eq 1 ] || { cat "$dir/ablation.txt"; fail "planar_wheel_ablation.py exited $rc with variants left out, not 1"; }
grep -q 'not checked, variant(s) graph-wheel,graph-planar not run' "$dir/ablation/table.md" ||
  { cat "$dir/ablation/table.md"; fail "the ablation table does not say which bar was not checked"; }
# --resume reuses the runs whose key matches (nothing simulated or run again) ...
/usr/bin/python3 "$root/scripts/planar_wheel_ablation.py" --out "$dir/ablation" --configs bridge_deck --seeds 1 \
  --duration 4 --variants graph,graph-bare,lio --resume >"$dir/ablation2.txt" 2>&1
# (its progress lines, one per log simulated and per run, start the line; the table's failures start with "- ")
if grep -Eq '^bridge_deck_s1: (simulating .*|graph|graph-bare|lio)$' "$dir/ablation2.txt"; then
  cat "$dir/ablation2.txt"; fail "--resume ran again what it had"
fi
# ... and a run whose key does not (its key file rewritten as if another binary had made it)
echo stale >"$dir/ablation/bridge_deck_s1/lio/evaluation_odometry.json.key"
/usr/bin/python3 "$root/scripts/planar_wheel_ablation.py" --out "$dir/ablation" --configs bridge_deck --seeds 1 \
  --duration 4 --variants graph,graph-bare,lio --resume >"$dir/ablation3.txt" 2>&1
grep -q '^bridge_deck_s1: lio$' "$dir/ablation3.txt" && ! grep -Eq '^bridge_deck_s1: graph(-bare)?$' "$dir/ablation3.txt" ||
  { cat "$dir/ablation3.txt"; fail "--resume did not run again exactly the run whose key changed"; }
echo "ablation table:"
/usr/bin/python3 "$root/tests/pipeline/check_variant_table.py" "$dir/ablation/table.md" bridge_deck 1 3 ||
  { cat "$dir/ablation.txt"; fail "the ablation table is not what it should be"; }

# The two LiDAR subsystems side by side with loop closure (lio_graph_gap_table.py) on 4 s of the room:
# both variants in the table; with one left out its bar is missed, not passed
/usr/bin/python3 "$root/scripts/lio_graph_gap_table.py" --out "$dir/gap" --configs room --seeds 1 \
  --duration 4 --variants graph-loop,lio-loop >"$dir/gap.txt" 2>&1
rc=$?
[ $rc -le 1 ] || { cat "$dir/gap.txt"; fail "lio_graph_gap_table.py exited $rc"; }
/usr/bin/python3 "$root/tests/pipeline/check_variant_table.py" "$dir/gap/table.md" room 1 2 ||
  { cat "$dir/gap.txt"; fail "the gap table is not what it should be"; }
grep -Eq '^- room: mean ATE graph-loop / lio-loop [0-9.]+x \(bar 1.5x\)$' "$dir/gap/table.md" ||
  { cat "$dir/gap/table.md"; fail "the gap table does not state the ratio of the mean ATEs"; }
/usr/bin/python3 "$root/scripts/lio_graph_gap_table.py" --out "$dir/gap" --configs room --seeds 1 \
  --duration 4 --variants graph-loop --resume >"$dir/gap2.txt" 2>&1 &&
  { cat "$dir/gap2.txt"; fail "lio_graph_gap_table.py passed with lio-loop left out"; }
grep -q 'not checked, variant(s) lio-loop not run' "$dir/gap/table.md" ||
  { cat "$dir/gap/table.md"; fail "the gap table does not say its bar was not checked"; }
echo "gap table: ok"
