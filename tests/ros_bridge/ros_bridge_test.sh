#!/usr/bin/env bash
# livo-ros-bridge end to end, on a private network namespace (scripts/private_bus.sh: ROS's TCP and
# LCM's multicast stay inside it). A simulated room walk (livo-sim) is written as a ROS 1 bag by
# ROS's own Python library (sim_log_to_bag.py), then run two ways:
#   import path  livo-import rosbag BAG -> LOG, livo-lio on it in lockstep (livo-playback), ODOMETRY
#                recorded by livo-record
#   ROS path     roscore; livo-lio; livo-ros-bridge; a rospy recorder of the bridge's nav_msgs/Odometry,
#                /tf and registered scans (ros_outputs_recorder.py); `rosbag play` of the bag in real
#                time; livo_ros_bridge_bus_recorder (bus_recorder.cpp: a subscription without LCM's
#                30-message queue limit, which lost IMU samples in lcm-logger under load) records
#                the sensor channels the bridge publishes
# Checks: the bridge's IMU, LIDAR and GROUND_TRUTH streams are byte-identical to the import's (one
# code path: livo-import rosbag's conversions); the ROS side received as many odometry poses as the
# import path made, each with its /tf, in the configured frames, and registered scans as PointCloud2;
# the ATE of both against the bag's ground truth agrees within the real-time tolerance below.
#
#   tests/ros_bridge/ros_bridge_test.sh REPO_ROOT BIN_DIR BUS_RECORDER
set -uo pipefail
root="$1"; bin="$2"; bus_recorder="$3"
if [ "${LIVO_PRIVATE_BUS:-}" != 1 ]; then exec "$root/scripts/private_bus.sh" "$0" "$@"; fi
dir=$(mktemp -d /tmp/livo-ros-bridge.XXXXXX)
cd "$dir"  # livo-lio writes calibration.csv/.yaml into its working directory
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null; done
  for _ in $(seq 50); do  # roscore takes a few seconds to stop its master and rosout
    alive=0; for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; done
  wait 2>/dev/null
  [ -n "${LIVO_KEEP_TEST_DIR:-}" ] && echo "kept $dir" >&2 || rm -rf "$dir"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$dir"/*.log; do [ -s "$f" ] && { echo "--- $(basename "$f")" >&2; tail -n 15 "$f" >&2; }; done
  exit 1
}
config="$root/config/sim/room.yaml"
duration=8
# Real-time tolerance on the ATE and on each pose (m). The bridge's sensor streams are checked
# byte-identical to the import's, and livo-lio's output depends only on its inputs' contents and
# stamps, never on their arrival times, so real time alone should change nothing: measured, the ATE
# differs by 2e-11 m and the poses by 7e-10 m (the TUM text's nine decimals). 1 mm, a fifth of the
# run's ATE (5.0 mm), leaves room for real time to matter where it may (a sweep that lio handles
# differently when it arrives late), and is far below what a wrong conversion does (a LiDAR stamp
# off by the 0.1 s sweep moves the poses by about 10 cm at 1 m/s).
ate_tolerance=0.001
start=$(date +%s)

# roscore first: it takes a few seconds to come up, while the bag is made and imported
export ROS_MASTER_URI=http://127.0.0.1:11411 ROS_IP=127.0.0.1 ROS_HOME="$dir/ros" ROS_LOG_DIR="$dir/ros/log"
mkdir -p "$ROS_LOG_DIR"
roscore -p 11411 >"$dir/roscore.log" 2>&1 &
roscore=$!

# ---- the bag -------------------------------------------------------------------------------------
"$bin/livo-sim" --config "$config" --no-images --out "$dir/sim.lcmlog" --duration "$duration" >"$dir/sim.log" 2>&1 ||
  fail "livo-sim failed"
/usr/bin/python3 "$root/tests/ros_bridge/sim_log_to_bag.py" "$dir/sim.lcmlog" "$dir/walk.bag" >"$dir/bag.log" 2>&1 ||
  fail "sim_log_to_bag.py failed"
echo "$(cat "$dir/bag.log")"
topics=(--imu /imu/data --lidar /velodyne_points --ground-truth /ground_truth/pose)

# ---- import path: livo-import rosbag + livo-lio in lockstep ----------------------------------------
"$bin/livo-import" rosbag "$dir/walk.bag" "${topics[@]}" --out "$dir/import.lcmlog" --quiet >"$dir/import.log" 2>&1 ||
  fail "livo-import failed"
"$bin/livo-lio" --config "$config" --name lio --quiet >"$dir/lio_lockstep.log" 2>&1 &
lio=$!
"$bin/livo-record" --out "$dir/import_outputs.lcmlog" --channels ODOMETRY --name record >"$dir/record.log" 2>&1 &
record=$!
pids=("$roscore" "$lio" "$record")
"$bin/livo-playback" "$dir/import.lcmlog" --lockstep --consumers lio,record --stall-timeout 60 \
  --startup-timeout 60 >"$dir/playback.log" 2>&1 || fail "lockstep replay failed"
kill -INT "$lio" "$record"; wait "$lio" "$record"
pids=()
n_import=$("$bin/livo-loginfo" "$dir/import_outputs.lcmlog" | awk '$1 == "ODOMETRY" { print $3 }')
[ -n "$n_import" ] || fail "the lockstep run made no odometry"
echo "import path: $(( $(date +%s) - start )) s so far"

# ---- ROS path: roscore, livo-lio, livo-ros-bridge, a rospy recorder, rosbag play --------------------
pids+=("$roscore")
# the kernel's UDP receive-buffer drops on this private bus, before and after (should stay 0)
rcvbuf_errors() { awk '$1 == "Udp:" && $2 ~ /^[0-9]/ { print $6 }' /proc/net/snmp; }
rcvbuf_before=$(rcvbuf_errors)
"$bus_recorder" 'IMU|LIDAR|GROUND_TRUTH|ODOMETRY' "$dir/bridge.lcmlog" >"$dir/bus_recorder.log" 2>&1 &
logger=$!
"$bin/livo-lio" --config "$config" --name lio >"$dir/lio_realtime.log" 2>&1 &
lio=$!
pids+=("$logger" "$lio")
"$bin/livo-ros-bridge" --config "$config" "${topics[@]}" --world-frame odom --body-frame base_link \
  >"$dir/bridge.log" 2>&1 &
bridge=$!
pids+=("$bridge")
/usr/bin/python3 "$root/tests/ros_bridge/ros_outputs_recorder.py" /livo/odometry /livo/registered_scan odom base_link \
  "$dir/ros_odometry.tum" "$dir/ros_summary.json" "$dir/ros_ready" >"$dir/recorder.log" 2>&1 &
recorder=$!
pids+=("$recorder")
for _ in $(seq 200); do [ -e "$dir/ros_ready" ] && break; sleep 0.1; done
[ -e "$dir/ros_ready" ] || fail "the recorder never connected to the bridge's outputs"
rosbag play -q --wait-for-subscribers "$dir/walk.bag" >"$dir/rosbag_play.log" 2>&1 || fail "rosbag play failed"
# the last sweeps' odometry: wait until the ROS side has as many poses as the lockstep run made, or
# until the count has not grown for 2 s; then 0.5 s more for a pose too many and the last /tf
last=-1; still=0
while [ "$still" -lt 10 ]; do
  n=$(wc -l <"$dir/ros_odometry.tum")
  [ "$n" -ge "$n_import" ] && break
  if [ "$n" = "$last" ]; then still=$((still + 1)); else still=0; fi
  last=$n
  sleep 0.2
done
sleep 0.5
kill -INT "$recorder"; wait "$recorder"
kill -INT "$bridge"; wait "$bridge" || fail "livo-ros-bridge exited non-zero"
kill -INT "$lio" "$logger"; wait "$lio"; wait "$logger" || fail "the bus recorder failed"
echo "bridge: $(grep 'ROS messages converted' "$dir/bridge.log")"
echo "bus recorder: $(cat "$dir/bus_recorder.log"); UDP receive-buffer drops: $(( $(rcvbuf_errors) - rcvbuf_before ))"
echo "whole run: $(( $(date +%s) - start )) s"

# ---- checks ------------------------------------------------------------------------------------------
"$bin/livo-loginfo" "$dir/import.lcmlog" --digest >"$dir/import_digest.txt" || fail "livo-loginfo import"
"$bin/livo-loginfo" "$dir/bridge.lcmlog" --digest >"$dir/bridge_digest.txt" || fail "livo-loginfo bridge"
"$bin/livo-loginfo" "$dir/import_outputs.lcmlog" --digest >"$dir/import_outputs.txt" || fail "livo-loginfo outputs"
evaluate() {  # NAME EST GT [ARGS]: livo-evaluate's JSON as DIR/NAME.json
  local name="$1" est="$2" gt="$3"; shift 3
  "$bin/livo-evaluate" --est "$est" --gt "$gt" --json "$dir/$name.json" "$@" >/dev/null 2>>"$dir/evaluate.log" ||
    fail "livo-evaluate $name"
}
evaluate import_eval "$dir/import_outputs.lcmlog:ODOMETRY" "$dir/import.lcmlog:GROUND_TRUTH"
evaluate ros_eval "$dir/ros_odometry.tum" "$dir/import.lcmlog:GROUND_TRUTH"
# the two estimates against each other, unaligned: how far the ROS path's poses are from the import path's
evaluate paths "$dir/ros_odometry.tum" "$dir/import_outputs.lcmlog:ODOMETRY" --align none
/usr/bin/python3 - "$dir" "$ate_tolerance" <<'PY' || fail "comparison"
import json, sys
d, tol = sys.argv[1], float(sys.argv[2])


def loginfo(path):
    """channel -> (count, digest) from livo-loginfo --digest (channel type count rate bytes unit digest)."""
    out = {}
    for line in open(path):
        f = line.split()
        if len(f) > 6 and f[0].isupper() and f[2].isdigit():
            out[f[0]] = (int(f[2]), f[6])
    return out


imp, bri, outs = loginfo(d + '/import_digest.txt'), loginfo(d + '/bridge_digest.txt'), loginfo(d + '/import_outputs.txt')
for ch in ('IMU', 'LIDAR', 'GROUND_TRUTH'):
    assert ch in imp and ch in bri, ('channel missing', ch, imp, bri)
    assert imp[ch] == bri[ch], ('%s differs between the import and the bridge' % ch, imp[ch], bri[ch])
print('sensor streams byte-identical: ' + ', '.join('%s %d' % (c, imp[c][0]) for c in ('IMU', 'LIDAR', 'GROUND_TRUTH')))
if bri.get('ODOMETRY') == outs['ODOMETRY']:
    print('ODOMETRY of the real-time livo-lio behind the bridge: byte-identical to the lockstep run\'s')
s = json.load(open(d + '/ros_summary.json'))
rows = sum(1 for l in open(d + '/ros_odometry.tum') if l.strip())
n_import = outs['ODOMETRY'][0]
print('ROS side: %d nav_msgs/Odometry %s, %d /tf odom->base_link, %d registered scans in %s (%s)' %
      (s['odometry'], s['odometry_frames'], s['tf'], s['scans'], s['scan_frames'], ' '.join(s['scan_fields'])))
assert s['odometry'] == rows == n_import, ('odometry count: ROS %d (%d rows), import path %d' % (s['odometry'], rows, n_import))
assert s['odometry_frames'] == [['odom', 'base_link']], s['odometry_frames']
assert s['tf'] == s['odometry'], ('one /tf per odometry', s['tf'], s['odometry'])
assert s['scans'] > 0 and s['scan_frames'] == ['odom'] and s['scan_points'] > 1000 * s['scans'], ('registered scans', s)
assert s['scan_fields'][:3] == ['x', 'y', 'z'], s['scan_fields']
ie, re_, pe = (json.load(open(d + '/%s.json' % n))['ate'] for n in ('import_eval', 'ros_eval', 'paths'))
print('ATE rmse: import path %.6f m (%d poses), ROS path %.6f m (%d poses), difference %.2e m (tolerance %g); '
      'ROS poses against the import path\'s, unaligned: rmse %.2e m, max %.2e m over %d'
      % (ie['rmse'], ie['count'], re_['rmse'], re_['count'], abs(ie['rmse'] - re_['rmse']), tol, pe['rmse'], pe['max'],
         pe['count']))
assert ie['count'] == re_['count'], ('matched poses', ie['count'], re_['count'])
assert abs(ie['rmse'] - re_['rmse']) <= tol, 'ATE differs by more than the tolerance'
assert pe['max'] <= tol, 'a ROS pose is further than the tolerance from the import path\'s'
PY
echo "whole test: $(( $(date +%s) - start )) s"
