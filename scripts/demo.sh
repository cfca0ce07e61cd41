#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, and runs the pipeline as far as it
# exists on bundled/shared data, on a private LCM bus.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"
out="${LIVO_DEMO_OUT:-$root/logs/demo}"

echo "== installing dependencies (Debian packages)"
"$root/scripts/install_deps.sh"
echo "== building"
"$root/scripts/build.sh" >/dev/null
mkdir -p "$out"

echo "== private bus: 50 x 1 MB point clouds at 10 Hz, recorded by lcm-logger"
"$root/scripts/private_bus.sh" bash -c '
  set -e
  lcm-logger --quiet -f "$1/bus.lcmlog" & logger=$!
  sleep 0.5; touch "$1/ready"
  "$2/bin/test-bus-publisher" "$1/ready"
  sleep 0.5; kill -INT $logger; wait $logger || true
  rm -f "$1/ready"' demo "$out" "$build"
"$build/bin/livo-loginfo" "$out/bus.lcmlog" | tee "$out/bus_loginfo.txt"
echo "== done: $out/bus_loginfo.txt"
