#!/usr/bin/env bash
# A ROS 2 bag of a run gives what the ROS 1 bag of the same run gives, through scripts/run_bag.sh.
# tests/tools/make_vlp16_bag.py (python3-rosbag) writes a ROS 1 bag of a generated walk (VLP-16,
# 200 Hz IMU, colour camera with camera_info, ground truth); rosbag2_fixtures/ros1_to_rosbag2.js
# converts it with other implementations than ours (@foxglove/rosbag reads it, CDR from
# @foxglove/rosmsg2-serialization, MCAP with zstd chunks from @mcap/core), and make_rosbag2_db3.py
# stores the same CDR in a .db3. Checks:
#   - livo-import rosbag2 of the .mcap and of the .db3 bag directory write the same log, byte for
#     byte, as livo-import rosbag of the ROS 1 bag;
#   - scripts/run_bag.sh on the ROS 1 bag and on the .mcap give the same ATE and the same odometry.
# 3 s of the walk (the ROS 1 bag's generation takes most of the time): 2 s at rest, then moving.
# Tolerance: none. The logs are byte-identical and run_pipeline.sh runs in lockstep (deterministic
# for a given log), so any difference in the ATE or the trajectory is a difference in the import.
#
#   tests/import/rosbag2_same_ate_test.sh REPO_ROOT BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-rosbag2-ate.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
template="$root/config/rigs/template_velodyne_vlp16.yaml"
tools="$root/tests/import/rosbag2_fixtures"
start=$(date +%s)
lap() { echo "[$(( $(date +%s) - start )) s] $*"; }

/usr/bin/python3 "$root/tests/tools/make_vlp16_bag.py" "$dir/walk.bag" --duration 3 --seed 2 2>"$dir/gen.err" \
  || { cat "$dir/gen.err"; fail "make_vlp16_bag.py failed"; }
lap generated; echo "ROS 1 bag: $(tail -n 1 "$dir/gen.err")"
mkdir -p "$dir/db3"
node "$tools/ros1_to_rosbag2.js" "$dir/walk.bag" "$dir/walk.mcap" --rows "$dir/db3/rows.json" 2>"$dir/conv.err" \
  || { cat "$dir/conv.err"; fail "ros1_to_rosbag2.js failed"; }
lap converted; grep "ros1_to_rosbag2:" "$dir/conv.err"
/usr/bin/python3 "$root/tests/import/make_rosbag2_db3.py" "$dir/db3" || fail "make_rosbag2_db3.py failed"

# The same log from the three bags.
import() {  # FORMAT INPUT NAME
  "$bin/livo-import" "$1" "$2" --out "$dir/$3.lcmlog" --ground-truth /ground_truth/pose --quiet >"$dir/$3.txt" \
    || { cat "$dir/$3.txt"; fail "livo-import $1 $2 failed"; }
}
import rosbag "$dir/walk.bag" ros1
import rosbag2 "$dir/walk.mcap" mcap
import rosbag2 "$dir/db3/bag_db3" db3
cmp "$dir/ros1.lcmlog" "$dir/mcap.lcmlog" || fail "the .mcap's log differs from the ROS 1 bag's"
cmp "$dir/ros1.lcmlog" "$dir/db3.lcmlog" || fail "the .db3's log differs from the ROS 1 bag's"
"$bin/livo-loginfo" "$dir/ros1.lcmlog" --digest | grep -E '^(IMU|LIDAR|CAMERA|GROUND_TRUTH) ' >"$dir/ros1.digest"
[ "$(wc -l <"$dir/ros1.digest")" = 4 ] || { cat "$dir/ros1.digest"; fail "the ROS 1 import lacks a channel"; }
lap imported; echo "the same log, byte for byte, from the ROS 1 bag, the .mcap and the .db3:"
sed 's/^/  /' "$dir/ros1.digest"

# The same run from the ROS 1 bag and from the .mcap (colour and octomap, whose outputs no estimator
# takes, left out to save time).
for bag in walk.bag walk.mcap; do
  "$root/scripts/run_bag.sh" "$dir/$bag" --rig "$template" --ground-truth /ground_truth/pose --without colour,octomap \
    --out "$dir/run_$bag" \
    >"$dir/run_$bag.out" 2>"$dir/run_$bag.err" || { cat "$dir/run_$bag.err"; fail "run_bag.sh $bag failed"; }
done
/usr/bin/python3 - "$dir/run_walk.bag" "$dir/run_walk.mcap" <<'PY' || exit 1
import json, sys
ros1, ros2 = sys.argv[1], sys.argv[2]
ate = [json.load(open(d + '/evaluation_odometry.json'))['ate']['rmse'] for d in (ros1, ros2)]
assert ate[0] == ate[1], ('ATE differs: ROS 1 %r, ROS 2 %r' % (ate[0], ate[1]))
odo = [open(d + '/odometry.tum').read() for d in (ros1, ros2)]
assert odo[0] == odo[1], 'odometry.tum differs'
rows = [l for l in odo[0].splitlines() if l.strip() and not l.startswith('#')]
assert len(rows) >= 15, ('odometry.tum has %d poses' % len(rows))
print('run_bag.sh: ROS 1 bag and ROS 2 .mcap: ATE rmse %.6f m both, %d identical poses' % (ate[0], len(rows)))
PY
echo "whole test: $(( $(date +%s) - start )) s"
