#!/usr/bin/env bash
# Runs the pipeline on live sensors: the processes on an LCM bus that the sensor drivers publish
# on, no playback, until Ctrl-C (SIGINT) or SIGTERM; then everything stops in order and DIR gets
# what scripts/run_pipeline.sh writes after a replay, made from what was recorded: outputs.lcmlog,
# the maps (colour_map.ply, octomap.bt, ...), odometry.tum, trajectory.tum, timing.json and
# report.md (evaluated against GROUND_TRUTH when something on the bus publishes it).
#
#   scripts/run_live.sh --config FILE --out DIR [--bus URL] [--processes P,...] [--without P,...]
#                       [--swap P=EXE] [--record CH,...] [--max-restarts N] [--stop-grace S]
#                       [--overlay FILE,...]
#
# --bus URL: the LCM bus (default: $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0, which
# stays on this machine; ttl=1 reaches the LAN). Processes: as run_pipeline.sh (those with a section
# in FILE). They are supervised as in real-time replays (--respawn: a process that exits is
# restarted, at most --max-restarts times, 3 by default). A process that outputs nothing (no sensor
# data yet) is not a failure.
# Dead sensors: livo-sensor-watch watches the rig's IMU and LiDAR channels; one silent for a second
# (wall clock) is a warning on stderr ("no IMU for 1.0 s", then "IMU back after 1.52 s ...") and a
# row of report.md's "Sensor gaps" (logs/sensor_gaps.tsv). The watch only listens: no estimator's
# output depends on the wall clock. At the stop each process gets SIGINT and --stop-grace seconds
# (60) to write its maps, then the recorder stops. The last line printed is report.md's path.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage() { sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "run_live.sh: $*" >&2; exit 1; }

config="" out="" bus="${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}"
pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --config) config="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --bus) bus="$2"; shift 2 ;;
    --processes|--without|--swap|--record|--max-restarts|--stop-grace|--overlay)
      [ $# -ge 2 ] || die "$1 takes a value"
      pass+=("$1" "$2"); shift 2 ;;
    -h|--help) usage 0 ;;
    *) echo "run_live.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[ -n "$config" ] && [ -n "$out" ] || usage
[ -f "$config" ] || die "no such config: $config"
[[ "$bus" == *://* ]] || die "--bus takes an LCM URL (udpm://ADDRESS:PORT?ttl=N), not '$bus'"
command -v setsid >/dev/null || die "'setsid' (util-linux) is not installed"

exec "$root/scripts/run_pipeline.sh" --live --bus "$bus" --config "$config" --out "$out" --respawn ${pass[@]+"${pass[@]}"}
