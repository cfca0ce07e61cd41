#!/usr/bin/env bash
# Installs what is missing (scripts/install_deps.sh, silent when nothing is), builds (if needed)
# and runs every test with ctest. Multi-process tests run on the private bus.
#   scripts/test.sh [ctest args...]      e.g. -R Config  or  -L slow
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j "${LIVO_TEST_JOBS:-2}" "$@"
