#!/usr/bin/env bash
# The lockstep replay that overlaps the processes (lio's quiet promises let IMU samples go on
# without waiting; colour, octomap and the recorder lag a bounded way behind) gives what the
# serial replay gives (--serial: every process handles every message before the next goes out):
# every recorded channel byte for byte (livo-loginfo --digest; HEALTH carries wall-clock timings,
# so it is left out) and every map and trajectory file. Room, all five processes.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-fast-lockstep.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
"$bin/livo-sim" --config "$root/config/sim/room.yaml" --out "$dir/room.lcmlog" --duration 10 --seed 4 --quiet \
  || fail "livo-sim failed"
for run in serial fast; do
  extra=(); [ "$run" = serial ] && extra=(--serial)
  "$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$root/config/sim/room.yaml" \
    --processes lio,vio,loop,colour,octomap --out "$dir/$run" "${extra[@]}" >/dev/null 2>"$dir/$run.err" \
    || { cat "$dir/$run.err"; fail "the $run run failed"; }
done
grep -q 'lockstep: serial' "$dir/serial/logs/playback.log" || fail "the serial run was not serial"
grep -q 'record, colour, octomap may lag up to 16 messages (16.0 MB)' "$dir/fast/logs/playback.log" \
  || { cat "$dir/fast/logs/playback.log"; fail "the fast run did not let the sinks lag"; }
# most messages went on at once (IMU under lio's promise, GROUND_TRUTH to the recorder alone)
summary=$(grep -E '^\[playback\] [0-9]+ messages, ' "$dir/fast/logs/playback.log")
total=$(sed -E 's/^\[playback\] ([0-9]+) messages.*/\1/' <<<"$summary")
early=$(sed -nE 's/.*; ([0-9]+) went on before the whole pipeline.*/\1/p' <<<"$summary")
[ -n "$early" ] && [ $(( early * 10 )) -ge $(( total * 7 )) ] || fail "only ${early:-0} of $total messages went on at once: $summary"
echo "$early of $total messages went on before the whole pipeline had handled them"
digests() { "$bin/livo-loginfo" --digest "$1/outputs.lcmlog" | awk '$1 ~ /^[A-Z_]+$/ && $1 != "HEALTH" {print $1, $3, $NF}'; }
digests "$dir/serial" >"$dir/serial.digests"
digests "$dir/fast" >"$dir/fast.digests"
for ch in ODOMETRY REGISTERED_SCAN KEYFRAME STATE_PRIOR STATE_POSTERIOR COLORED_CLOUD GROUND_TRUTH; do
  grep -q "^$ch " "$dir/serial.digests" || { cat "$dir/serial.digests"; fail "no $ch recorded"; }
done
diff "$dir/serial.digests" "$dir/fast.digests" >&2 || fail "recorded channels differ between the serial and the fast replay"
for f in odometry.tum trajectory.tum keyframes.tum colour_map.ply octomap.bt octomap.ot global_map.ply; do
  [ -s "$dir/serial/$f" ] || fail "the serial run wrote no $f"
  cmp -s "$dir/serial/$f" "$dir/fast/$f" || fail "$f differs between the serial and the fast replay"
done
echo "serial and fast lockstep: identical channels ($(wc -l <"$dir/serial.digests")) and files"
grep -E '^\[playback\] [0-9]+ messages' "$dir/serial/logs/playback.log" "$dir/fast/logs/playback.log"
