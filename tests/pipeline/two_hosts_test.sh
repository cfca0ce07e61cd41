#!/usr/bin/env bash
# Two hosts (issue 46): the pipeline split over a "robot" (playback, lio, vio) and a "base station"
# (loop, colour, octomap and the recorder), two network namespaces joined by a veth pair
# (scripts/two_hosts.sh), the bus a udpm URL with ttl=1 that crosses the link, lockstep across both,
# gives what the one-host run gives: every recorded channel (livo-loginfo --digest; HEALTH and
# PROGRESS carry wall-clock timings) and every map and trajectory file (md5), as
# scripts/output_digests.sh compares them. Room with images, 8 s, seed 3. Before that: the
# namespaces and the link are what they should be, and a ttl=0 bus does not cross the link.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-two-hosts-test.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
config="$root/config/sim/room.yaml"
"$bin/livo-sim" --config "$config" --out "$dir/room.lcmlog" --duration 8 --seed 3 --quiet || fail "livo-sim failed"

# The topology: two namespaces, neither the host's (two_hosts.sh checks that each has only lo and
# its end of the link), the robot's end reaching the base station's address (the base station
# stays until the robot is done: the link goes with its namespace).
"$root/scripts/two_hosts.sh" \
  --base bash -c 'readlink /proc/self/ns/net >"$0/base.ns"; ip -o addr show lan-base >"$0/base.addr"
                  trap "exit 0" TERM; sleep 60 & wait' "$dir" \
  --robot bash -c 'readlink /proc/self/ns/net >"$0/robot.ns"; ip route get 10.76.67.2 >"$0/robot.route";
                   ip route show >"$0/robot.mroute"; echo "$LCM_DEFAULT_URL" >"$0/robot.url"' "$dir" \
  || fail "two_hosts.sh could not set up the two namespaces"
host_ns=$(readlink /proc/self/ns/net)
base_ns=$(cat "$dir/base.ns"); robot_ns=$(cat "$dir/robot.ns")
[ "$base_ns" != "$robot_ns" ] && [ "$base_ns" != "$host_ns" ] && [ "$robot_ns" != "$host_ns" ] \
  || fail "the namespaces are not three: host $host_ns, robot $robot_ns, base $base_ns"
grep -q 'inet 10.76.67.2/24' "$dir/base.addr" || { cat "$dir/base.addr"; fail "the base station's end has no address"; }
grep -q '^10.76.67.2 dev lan-robot ' "$dir/robot.route" || { cat "$dir/robot.route"; fail "the robot does not reach the base station over the link"; }
grep -q '^224.0.0.0/4 dev lan-robot' "$dir/robot.mroute" || fail "multicast is not routed on the robot's end"
grep -q '?ttl=1&' "$dir/robot.url" || fail "the bus URL does not cross one hop: $(cat "$dir/robot.url")"

# ttl=0 (the private bus's) does not leave its host: none of the test publisher's 50 clouds reaches
# the base station (its subscriber is stopped when the robot is done), so what crosses below crosses
# by the ttl=1 URL.
LIVO_LCM_URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608' "$root/scripts/two_hosts.sh" \
  --base "$bin/test-bus-subscriber" "$dir/bus.ready" --robot "$bin/test-bus-publisher" "$dir/bus.ready" \
  >"$dir/ttl0.out" 2>&1
grep -q '^published 50 clouds' "$dir/ttl0.out" && grep -q '^received 0/50,' "$dir/ttl0.out" \
  || { cat "$dir/ttl0.out"; fail "with ttl=0 the robot's messages reached the base station (or none was sent)"; }

# One host: the five processes on a private bus (no report: the trajectories extracted alone).
"$root/scripts/private_bus.sh" "$root/scripts/run_pipeline.sh" --inside-bus --log "$dir/room.lcmlog" --config "$config" \
  --processes lio,vio,loop,colour,octomap --out "$dir/one" >/dev/null 2>"$dir/one.err" \
  || { cat "$dir/one.err"; fail "the one-host run failed"; }
"$bin/livo-report" extract "$dir/one/outputs.lcmlog" --dir "$dir/one" 2>"$dir/one.extract" \
  || { cat "$dir/one.extract"; fail "livo-report extract failed on the one-host run"; }

# Two hosts: the base station waits for the replay (--no-playback) and records; the robot replays
# and waits in lockstep for the base station's processes as for its own (--remote).
url='udpm://239.255.76.67:7667?ttl=1&recv_buf_size=8388608'
"$root/scripts/two_hosts.sh" \
  --base "$root/scripts/run_pipeline.sh" --bus "$url" --log "$dir/room.lcmlog" --config "$config" \
         --processes loop,colour,octomap --no-playback --out "$dir/base" \
  --robot "$root/scripts/run_pipeline.sh" --bus "$url" --log "$dir/room.lcmlog" --config "$config" \
         --processes lio,vio --remote loop,colour,octomap,record --out "$dir/robot" \
  >"$dir/two.out" 2>"$dir/two.err" || { tail -n 30 "$dir/two.err"; fail "the two-host run failed"; }
grep -q 'lockstep: record, colour, octomap may lag up to 16 messages' "$dir/robot/logs/playback.log" \
  || { cat "$dir/robot/logs/playback.log"; fail "the robot's replay did not let the base station's sinks lag"; }
! grep -q 'lost on the bus' "$dir/robot/logs/playback.log" || fail "messages were lost on the link: $(grep 'lost on the bus' "$dir/robot/logs/playback.log")"
[ -s "$dir/base/report.md" ] || fail "the base station wrote no report.md"
[ ! -e "$dir/robot/outputs.lcmlog" ] || fail "the robot recorded too"
for p in loop colour octomap; do [ ! -e "$dir/robot/logs/$p.log" ] || fail "$p ran on the robot"; done
for p in lio vio; do [ ! -e "$dir/base/logs/$p.log" ] || fail "$p ran on the base station"; done

digests() { "$bin/livo-loginfo" --digest "$1/outputs.lcmlog" | awk '$1 ~ /^[A-Z_]+$/ && $1 != "HEALTH" && $1 != "PROGRESS" {print $1, $3, $NF}'; }
digests "$dir/one" >"$dir/one.digests"
digests "$dir/base" >"$dir/two.digests"
for ch in ODOMETRY REGISTERED_SCAN KEYFRAME STATE_PRIOR STATE_POSTERIOR COLORED_CLOUD OCTOMAP GROUND_TRUTH; do
  grep -q "^$ch " "$dir/one.digests" || { cat "$dir/one.digests"; fail "no $ch recorded"; }
done
diff "$dir/one.digests" "$dir/two.digests" >&2 || fail "recorded channels differ between one host and two"
# where each file is written: lio's on the robot, the rest (and what report extract makes of the
# recording) on the base station
files=0
for f in calibration.csv calibration.yaml; do
  [ -s "$dir/one/$f" ] || fail "the one-host run wrote no $f"
  cmp -s "$dir/one/$f" "$dir/robot/$f" || fail "$f differs between one host and the robot"
  files=$((files + 1))
done
for f in odometry.tum trajectory.tum keyframes.tum loops.json global_map.ply colour_map.ply colour_map.pcd octomap.bt octomap.ot; do
  [ -s "$dir/one/$f" ] || fail "the one-host run wrote no $f"
  [ "$(md5sum <"$dir/one/$f")" = "$(md5sum <"$dir/base/$f")" ] || fail "$f differs between one host and the base station"
  files=$((files + 1))
done
echo "one host and two: identical channels ($(wc -l <"$dir/one.digests")) and files ($files)"
grep -E '^\[playback\] [0-9]+ messages' "$dir/one/logs/playback.log" "$dir/robot/logs/playback.log"
