#!/usr/bin/env bash
# A camera triggered by the LiDAR costs no LiDAR update (issue 15): config/sim/room_triggered.yaml
# (10 Hz camera) with sim.camera.trigger sweep_end, sweep_start and free, 6 s each, through
# scripts/run_pipeline.sh with lio + vio and with lio alone. For every timing: lio refuses no sweep,
# publishes ODOMETRY for as many sweeps as LiDAR-only, and hands off every image after the map is
# seeded, almost all of them updated by the VIO.
#   tests/pipeline/camera_trigger_test.sh SOURCE_DIR BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-camera-trigger.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
base="$root/config/sim/room_triggered.yaml"
grep -q '^    trigger: sweep_end$' "$base" || fail "$base no longer sets sim.camera.trigger: sweep_end"

published() { sed -n "s/^  published $2: \([0-9]*\)$/\1/p" "$1/logs/lio.log"; }

for trigger in sweep_end sweep_start free; do
  config="$dir/$trigger.yaml"
  sed -e "s/^    trigger: sweep_end$/    trigger: $trigger/" \
      -e "s#^  scene_file: scenes/#  scene_file: $root/config/sim/scenes/#" "$base" > "$config"
  log="$dir/$trigger.lcmlog"
  "$bin/livo-sim" --config "$config" --out "$log" --duration 6 --quiet 2>"$dir/sim.err" \
    || { cat "$dir/sim.err"; fail "livo-sim ($trigger) failed"; }
  for procs in lio,vio lio; do
    "$root/scripts/run_pipeline.sh" --log "$log" --config "$config" --processes "$procs" \
      --out "$dir/$trigger-$procs" >/dev/null 2>"$dir/run.err" \
      || { cat "$dir/run.err"; fail "$trigger $procs run failed"; }
  done
  livo="$dir/$trigger-lio,vio" lio="$dir/$trigger-lio"
  refused=$(grep -c "sweep ends before the filter time" "$livo/logs/lio.log")
  odo_livo=$(published "$livo" ODOMETRY) odo_lio=$(published "$lio" ODOMETRY)
  priors=$(published "$livo" STATE_PRIOR)
  handoff=$(grep "camera hand-off:" "$livo/logs/lio.log")
  images=$("$bin/livo-loginfo" "$log" | awk '$1 == "CAMERA" {print $3}')
  echo "$trigger: ODOMETRY $odo_livo with the VIO, $odo_lio LiDAR-only; $images images, $priors priors; $refused sweeps refused; $handoff"
  [ "$refused" = 0 ] || fail "$trigger: lio refused $refused sweeps with the VIO running"
  [ -n "$odo_livo" ] && [ "$odo_livo" = "$odo_lio" ] \
    || fail "$trigger: ODOMETRY for $odo_livo sweeps with the VIO, $odo_lio LiDAR-only"
  /usr/bin/python3 - "$trigger" "$images" "$odo_livo" "$priors" "$handoff" <<'PY' || exit 1
import re, sys
trigger, images, sweeps, priors, handoff = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
adopted = int(re.search(r'(\d+) posteriors adopted', handoff).group(1))
unanswered = int(re.search(r'(\d+) unanswered', handoff).group(1))
# images before the map is seeded (the IMU initialisation) are skipped: at most a second of them
assert priors >= images - 12, (trigger, 'priors', priors, 'of', images, 'images')
assert unanswered == 0, (trigger, handoff)
assert adopted >= priors - 3, (trigger, handoff)  # the first images find an empty point-patch map
assert sweeps >= 50, (trigger, 'sweeps registered', sweeps)
PY
done
echo "every sweep registered with the camera at the sweep end, the sweep start and free-running"
