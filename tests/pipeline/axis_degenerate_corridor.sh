#!/usr/bin/env bash
# axis_degenerate_corridor.sh ROOT OUT: writes to OUT config/sim/corridor.yaml with a 50 m LiDAR.
# The corridor's end walls are 72-128 m from its walk, the nearer one within the OS1-16's 100 m
# except near the middle: a handful of rows per sweep, which livo-lio uses (issue 43). Beyond a
# 50 m LiDAR's reach the corridor is degenerate along its axis all the way, as the tests of what
# happens there need.
set -euo pipefail
root="$1" out="$2"
sed -e 's|max_range: 100.0|max_range: 50.0|' \
    -e "s|scene_file: scenes/corridor.yaml|scene_file: $root/config/sim/scenes/corridor.yaml|" \
    "$root/config/sim/corridor.yaml" > "$out"
grep -q 'max_range: 50.0' "$out" || { echo "config/sim/corridor.yaml: no 'max_range: 100.0' to shorten" >&2; exit 1; }
grep -q "scene_file: $root/" "$out" || { echo "config/sim/corridor.yaml: no scene_file to make absolute" >&2; exit 1; }
