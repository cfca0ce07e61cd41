# Sourced by the pipeline tests that replay the simulated room with faults on its inputs; the
# sourcing script has set root, dir and fail() and written "$dir/room.lcmlog".

# check_input_faults MIN_POSES [run_pipeline.sh options]: the room through the LIO (swapped or joined
# as the options say) with NaN points, corrupted and dropped messages, duplicated and reordered IMU
# samples and a dead LiDAR second: the run finishes, never publishes NaN, gives at least MIN_POSES
# poses and stays under the LIO's 5 cm bar.
check_input_faults() {
  local min_poses="$1"
  shift
  "$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$root/config/sim/room.yaml" --processes lio \
    "$@" --out "$dir/faults" --seed 5 \
    --faults "nan:LIDAR:0.3,corrupt:LIDAR:0.05,drop:IMU:0.05,duplicate:IMU:0.05,reorder:IMU:0.05,cut:LIDAR:3:4" \
    >/dev/null 2>"$dir/faults.err" || { cat "$dir/faults.err"; fail "the run with faults failed"; }
  /usr/bin/python3 - "$dir/faults" "$min_poses" <<'PY' || exit 1
import json, math, sys
d = sys.argv[1]
rows = [[float(x) for x in l.split()] for l in open(d + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert all(math.isfinite(v) for r in rows for v in r), 'NaN in the odometry'
assert len(rows) >= int(sys.argv[2]), len(rows)
e = json.load(open(d + '/evaluation_odometry.json'))
assert e['ate']['rmse'] < 0.05, e['ate']
print('with faults: %d poses, ATE rmse %.4f m' % (len(rows), e['ate']['rmse']))
PY
}
