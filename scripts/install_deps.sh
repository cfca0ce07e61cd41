#!/usr/bin/env bash
# Installs every build, run and test dependency of livo-lcm from Debian 12 packages (apt only).
# Every Python module the tests and scripts import comes from a package listed here
# (ctest's Tools.PythonDepsPackaged checks it).
# Idempotent: does nothing (and prints nothing) when everything is already installed.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  # middleware: LCM C/C++ library, lcm-gen / lcm-logger / lcm-logplayer, Java bindings for lcm-spy
  liblcm-dev libglib2.0-dev liblcm-bin liblcm-java libjchart2d-java default-jdk-headless
  # math, geometry, vision, mapping, optimisation
  libeigen3-dev libpcl-dev libopencv-dev liboctomap-dev libceres-dev libflann-dev
  libnanoflann-dev libyaml-cpp-dev liblz4-dev libbz2-dev zlib1g-dev
  # tests and benchmarks
  googletest libgtest-dev libgmock-dev libbenchmark-dev python3
  # livo-import: Ouster metadata JSON; ROS 1 bags written by the real ROS library in its tests
  nlohmann-json3-dev python3-rosbag python3-roslz4 python3-rospy python3-std-msgs
  python3-sensor-msgs python3-geometry-msgs python3-nav-msgs python3-numpy
  # livo-ros-bridge (optional at build time: built when these are there): roscpp, raw subscriptions
  # (topic_tools::ShapeShifter), tf2_ros, the output messages' headers; its test: roscore
  # (roslaunch, rosmaster, rosout) and /tf read from Python
  libroscpp-dev libtopic-tools-dev libtf2-ros-dev libnav-msgs-dev libsensor-msgs-dev libgeometry-msgs-dev
  python3-roslaunch python3-rosmaster rosout python3-tf2-msgs
  # livo-import rosbag2: MCAP chunks compressed with zstd (lz4: liblz4-dev above), SQLite bags (.db3)
  libzstd-dev libsqlite3-dev
  # report.html: three.js inlined into the page; headless Chromium renders it in the report tests
  libjs-three chromium fonts-dejavu-core
  # private bus (network namespaces) and process tools
  iproute2 util-linux procps
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# Test tooling on npm (livo-import's rosbag2 fixtures): Debian's npm (and nodejs) only when no npm is
# on the PATH (a nodejs that bundles npm, e.g. nodesource's, conflicts with Debian's npm package).
command -v npm >/dev/null 2>&1 || missing+=(npm)

# The node modules of npm test tooling, from each package-lock.json (idempotent and quiet).
npm_test_tooling() {
  local root dir
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  for dir in "$root/tests/import/rosbag2_fixtures"; do
    [ -f "$dir/package-lock.json" ] || continue
    [ "$dir/node_modules/.package-lock.json" -nt "$dir/package-lock.json" ] && continue
    npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error >/dev/null || {
      echo "install_deps.sh: npm ci failed in $dir" >&2
      exit 1
    }
  done
}
if [ ${#missing[@]} -eq 0 ]; then
  npm_test_tooling
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
echo "install_deps.sh: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
log=$(mktemp /tmp/livo-install-deps.XXXXXX.log)
if ! { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
  echo "install_deps.sh: apt failed; last lines of $log:" >&2
  tail -n 30 "$log" >&2
  exit 1
fi
rm -f "$log"
npm_test_tooling
