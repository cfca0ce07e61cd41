#!/usr/bin/env bash
# Images that arrive late still reach the VIO in real time (issue 15): a 12 s simulated room run
# (free-running 20 Hz camera) through lio + vio in lockstep, then with --realtime and every CAMERA
# message delayed by 50 ms and by 80 ms (livo-playback --faults delay:CAMERA:1:S). A sweep waits
# for the images before its end (lio.image_max_wait_s, 0.1 s) so at least 95 % of the priors of the
# lockstep run are handed off. Without the wait (image_max_wait_s: 0) the 80 ms run handed off half
# of them: an image behind the filter time is dropped.
#   tests/pipeline/late_images_test.sh SOURCE_DIR BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-late-images.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
config="$root/config/sim/room.yaml"
"$bin/livo-sim" --config "$config" --out "$dir/room.lcmlog" --duration 12 --seed 5 --quiet || fail "livo-sim failed"

priors() { sed -n 's/^\[lio\] camera hand-off: \([0-9]*\) priors.*/\1/p' "$dir/$1/logs/lio.log" | tail -n 1; }
run() {  # run NAME [run_pipeline.sh options...]
  local name="$1"; shift
  "$root/scripts/run_pipeline.sh" --log "$dir/room.lcmlog" --config "$config" --processes lio,vio --out "$dir/$name" "$@" \
    >/dev/null 2>"$dir/$name.err" || { tail -n 30 "$dir/$name.err"; fail "run $name failed"; }
}
run lockstep
lockstep=$(priors lockstep)
[ -n "$lockstep" ] && [ "$lockstep" -ge 200 ] || fail "lockstep handed off ${lockstep:-no} priors"
for delay in 0.05 0.08; do
  run "late$delay" --realtime --faults "delay:CAMERA:1:$delay"
  n=$(priors "late$delay")
  echo "images $delay s late: $n priors in real time, $lockstep in lockstep"
  [ -n "$n" ] && [ $((n * 100)) -ge $((lockstep * 95)) ] \
    || fail "images $delay s late: ${n:-no} priors of $lockstep reached the VIO"
done
echo "late images: ok"
