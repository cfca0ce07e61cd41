#!/usr/bin/env bash
# A ROS 1 bag (or a ROS 2 bag: its directory, a .mcap or a .db3) through the whole pipeline in one
# command, into --out:
#   input.lcmlog (+ .meta.yaml)   the bag imported by livo-import rosbag (rosbag2), on the rig's channel names
#   rig_from_bag.yaml             a starter rig from what the bag told (livo-import --rig-out): rates,
#                                 LiDAR rings and model, camera size, colour and camera_info
#                                 calibration; "REPLACE:" marks what the bag could not tell
#   logs/import.txt               the import's summary and the rig check
#   report.md, report.html and everything else scripts/run_pipeline.sh writes (accuracy against the
#                                 bag's ground truth when there is one)
#
#   scripts/run_bag.sh BAG --rig FILE --out DIR [--preset NAME] [--ground-truth FILE|TOPIC]
#                      [--imu TOPIC] [--lidar TOPIC] [--camera TOPIC] [--camera-info TOPIC]
#                      [--depth TOPIC] [--lidar-stamp start|end] [--sweep-duration S]
#                      [--lidar-rings N] [--lidar-time-field NAME] [--lidar-time-unit U]
#                      [--imu-accel-unit U] [--imu-gyro-unit U] [--use-bag-time] [--no-azimuth-times]
#                                                                          (livo-import rosbag)
#                      [--without P,...] [--swap P=EXE] [--processes P,...] [--overlay FILE,...]
#                      [--realtime] [--respawn|--no-respawn] [--calibrate-camera] [--faults F,...]
#                      [--seed N] [--max-restarts N] [--kill P:SIG:AT_S] [--stop-grace S]
#                      [--record CH,...]                                        (run_pipeline.sh)
# Before anything runs, the rig must pass --check-config of every process it has a section for. The
# rig is then checked against the bag: an image size that differs from the rig's camera, a sensor
# the rig needs that the bag lacks, stop the run (an error naming both values); intrinsics against
# the bag's camera_info, rates and the LiDAR model's ring count are warnings. Topics are found by
# type when the bag has one of each (else give them; `build/bin/livo-import rosbag BAG --list-topics`).
# Its last lines (stdout) are the paths of report.md and report.html; progress goes to stderr.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$(cd "${LIVO_BUILD_DIR:-$root/build}" 2>/dev/null && pwd)/bin" || bin="$root/build/bin"

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit "${1:-2}"; }
die() { echo "run_bag.sh: $*" >&2; exit 1; }
say() { echo "run_bag.sh: $*" >&2; }

bag="" rig="" out="" import_args=() pipeline_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --rig) rig="${2:-}"; shift 2 || usage ;;
    --out) out="${2:-}"; shift 2 || usage ;;
    --preset|--ground-truth|--imu|--lidar|--camera|--camera-info|--depth|--lidar-stamp|--sweep-duration|\
    --lidar-rings|--lidar-time-field|--lidar-time-unit|--imu-accel-unit|--imu-gyro-unit)
      [ $# -ge 2 ] || usage; import_args+=("$1" "$2"); shift 2 ;;
    --use-bag-time|--no-azimuth-times) import_args+=("$1"); shift ;;
    --without|--swap|--processes|--record|--faults|--seed|--max-restarts|--kill|--stop-grace|--overlay)
      [ $# -ge 2 ] || usage; pipeline_args+=("$1" "$2"); shift 2 ;;
    --realtime|--respawn|--no-respawn|--calibrate-camera) pipeline_args+=("$1"); shift ;;
    --log|--config) die "$1 is run_pipeline.sh's: run_bag.sh makes the log from BAG and runs --rig" ;;
    -h|--help) usage 0 ;;
    -*) echo "run_bag.sh: unknown option '$1'" >&2; usage ;;
    *) [ -z "$bag" ] || { echo "run_bag.sh: one bag only ('$bag', then '$1')" >&2; usage; }
       bag="$1"; shift ;;
  esac
done
[ -n "$bag" ] && [ -n "$rig" ] && [ -n "$out" ] || usage
[ -f "$bag" ] || [ -d "$bag" ] || die "no such bag: $bag"
format=rosbag
case "$bag" in *.mcap|*.db3) format=rosbag2 ;; esac
[ -d "$bag" ] && format=rosbag2
[ -f "$rig" ] || die "no such rig: $rig (config/rigs/ has templates and dataset rigs; livo-import --rig-out writes a starter)"
for tool in livo-import livo-loginfo; do
  [ -x "$bin/$tool" ] || die "$bin/$tool missing: run scripts/build.sh"
done

# The rig as every process it starts reads it (run_pipeline.sh starts those with a section).
checked=0
for p in lio vio vio_feature loop colour octomap; do
  grep -Eq "^$p:" "$rig" || continue
  exe="$bin/livo-${p//_/-}"
  [ -x "$exe" ] || die "$exe missing: run scripts/build.sh (the rig has a $p: section)"
  if ! msg=$("$exe" --config "$rig" --check-config --lcm-url nosuch:// 2>&1); then
    die "the rig $rig fails livo-${p//_/-} --check-config: $(echo "$msg" | grep -v '^ ' | tail -n 1)"
  fi
  checked=$((checked + 1))
done
[ "$checked" -gt 0 ] || die "the rig $rig has none of the sections lio, vio, vio_feature, loop, colour, octomap: nothing would run"

mkdir -p "$out/logs"
log="$out/input.lcmlog"
say "importing $bag -> $log (starter rig: $out/rig_from_bag.yaml; summary: $out/logs/import.txt)"
rc=0
"$bin/livo-import" "$format" "$bag" --out "$log" --rig-out "$out/rig_from_bag.yaml" --rig "$rig" \
  ${import_args[@]+"${import_args[@]}"} >"$out/logs/import.txt" || rc=$?
# the channel table for the person at the terminal (livo-import printed the rig check on stderr)
sed -n '/^channel /,/^total /p' "$out/logs/import.txt" | sed 's/^/  /' >&2
case "$rc" in
  0) ;;
  1) [ -s "$log" ] || die "the import failed (see $out/logs/import.txt)"
     say "warning: the bag could not be read to its end (see $out/logs/import.txt); going on with what was read" ;;
  3) die "the rig $rig does not fit the bag (errors above); $out/rig_from_bag.yaml holds what the bag told" ;;
  *) die "livo-import failed (exit $rc; see $out/logs/import.txt)" ;;
esac
"$bin/livo-loginfo" "$log" | grep -q '^GROUND_TRUTH ' ||
  say "no ground truth in the log: the report has no accuracy figures (give --ground-truth FILE|TOPIC)"

rc=0
"$root/scripts/run_pipeline.sh" --log "$log" --config "$rig" --out "$out" ${pipeline_args[@]+"${pipeline_args[@]}"} \
  >/dev/null || rc=$?
[ "$rc" = 0 ] || die "the pipeline failed (exit $rc; outputs so far in $out, see $out/logs/)"
out="$(cd "$out" && pwd)"
[ -f "$out/report.md" ] || die "the pipeline wrote no report.md in $out"
echo "$out/report.md"
if [ -f "$out/report.html" ]; then
  echo "$out/report.html"
else
  say "warning: no report.html in $out (this build's run_pipeline.sh writes none); report.md has it all"
fi
