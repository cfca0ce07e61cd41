#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, simulates a default sequence (the
# furnished room: VLP-16, 200 Hz IMU, 20 Hz camera) and runs the whole pipeline on it on a private
# LCM bus. Ends with the path of the report.
#   scripts/demo.sh [CONFIG] [DURATION_S]      defaults: config/sim/room.yaml 30
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"
config="${1:-$root/config/sim/room.yaml}"
duration="${2:-30}"
name="$(basename "$config" .yaml)"
log="$root/logs/${name}_${duration}s.lcmlog"
out="$root/logs/demo_$name"

echo "== installing dependencies (Debian packages)" >&2
"$root/scripts/install_deps.sh"
echo "== building (build.log)" >&2
"$root/scripts/build.sh" >"$root/logs/build.log" 2>&1 || { tail -n 30 "$root/logs/build.log" >&2; exit 1; }
if [ ! -s "$log" ] || [ "$log" -ot "$config" ]; then
  echo "== simulating $duration s of $name -> $log" >&2
  "$build/bin/livo-sim" --config "$config" --out "$log" --duration "$duration" --seed 1 >&2
fi
echo "== running the pipeline" >&2
"$root/scripts/run_pipeline.sh" --log "$log" --config "$config" --out "$out"
