#!/usr/bin/env bash
# Inside the private bus: lcm-logger records 50 point clouds; livo-loginfo must report them.
set -euo pipefail
pub="$1"
loginfo="$2"
dir=$(mktemp -d /tmp/livo-loginfo-test.XXXXXX)
trap 'rm -rf "$dir"' EXIT
lcm-logger --quiet -f "$dir/bus.lcmlog" &
logger=$!
sleep 0.5            # let the logger subscribe
touch "$dir/ready"
"$pub" "$dir/ready"
sleep 0.5
kill -INT "$logger"
wait "$logger" || true
"$loginfo" "$dir/bus.lcmlog" | tee "$dir/info.txt"
# the publisher paces itself with sleeps: on a loaded machine 50 messages span a little more than 4.9 s
grep -Eq '^BUS_TEST +livo\.point_cloud_t +50 +(9\.[5-9]|10\.[0-4])[0-9]* ' "$dir/info.txt" || {
  echo "FAIL: expected 50 livo.point_cloud_t messages at ~10 Hz on BUS_TEST" >&2
  exit 1
}
