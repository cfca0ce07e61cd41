#!/usr/bin/env bash
# Configures and builds livo-lcm into build/ (RelWithDebInfo: -O2, debug line tables, -DLIVO_DEBUG_INFO=full for -g;
# debug sections compressed). Executables: build/bin/livo-*.
#   scripts/build.sh [extra cmake args...]      e.g. -DCMAKE_BUILD_TYPE=Release
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"
jobs="${LIVO_JOBS:-$(nproc)}"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${LIVO_BUILD_TYPE:-RelWithDebInfo}" "$@" >"$build.configure.log" 2>&1 || {
  cat "$build.configure.log" >&2
  echo "build.sh: cmake configuration failed (log above; missing packages? run scripts/install_deps.sh)" >&2
  exit 1
}
rm -f "$build.configure.log"
cmake --build "$build" -j "$jobs"
