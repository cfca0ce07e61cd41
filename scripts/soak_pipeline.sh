#!/usr/bin/env bash
# Whole-pipeline memory soak (issue 16; a benchmark, not a ctest test: the full run takes hours on
# two cores). Simulates the soak log if it is not there yet, runs every process on it as the demo
# does (scripts/run_pipeline.sh: lockstep, private bus), then prints per process the peak RSS at
# the checkpoints of sensor time (from the HEALTH messages in outputs.lcmlog), the ATE and the
# sizes of the maps.
#
#   scripts/soak_pipeline.sh [--config FILE] [--duration S] [--log LOG] [--out DIR] [--at S,S,...]
#                            [--without P,...] [--swap P=EXE]   (passed to run_pipeline.sh)
#
# Defaults: config/sim/campus_loop_long_soak.yaml, 1800 s, logs/campus_loop_long_soak_<S>s.lcmlog,
# logs/soak_<config name>_<S>s, checkpoints 300, 900 and 10 s before the end (those beyond the
# duration print '-'): the last one before the processes' exit work (writing the maps), which
# only the "whole run" column takes in.
# Bar (issue 16): each process's RSS at 30 min within 20 % of its value at 5 min, none above 1 GB.
set -euo pipefail
# One brace group: bash reads all of it before running any of it, so editing this file during a
# long run (a 30 min soak) cannot break that run.
{
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$(cd "${LIVO_BUILD_DIR:-$root/build}" 2>/dev/null && pwd)/bin" || bin="$root/build/bin"
config="$root/config/sim/campus_loop_long_soak.yaml" duration=1800 log="" out="" at="" without=() swap=()
while [ $# -gt 0 ]; do
  case "$1" in
    --config) config="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --log) log="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --at) at="$2"; shift 2 ;;
    --without) without=(--without "$2"); shift 2 ;;
    --swap) swap+=(--swap "$2"); shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "soak_pipeline.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
name="$(basename "$config" .yaml)"
at="${at:-300,900,$(awk -v d="$duration" 'BEGIN { print (d > 10 ? d - 10 : d) }')}"
log="${log:-$root/logs/${name}_${duration}s.lcmlog}"
out="${out:-$root/logs/soak_${name}_${duration}s}"
for tool in livo-sim livo-report; do
  [ -x "$bin/$tool" ] || { echo "soak_pipeline.sh: $bin/$tool missing: run scripts/build.sh" >&2; exit 1; }
done
mkdir -p "$(dirname "$log")"
if [ ! -f "$log" ]; then
  echo "soak_pipeline.sh: simulating $duration s of $name -> $log" >&2
  t0=$(date +%s)
  "$bin/livo-sim" --config "$config" --out "$log.part" --duration "$duration" >&2
  mv "$log.part" "$log"
  echo "soak_pipeline.sh: simulated in $(( $(date +%s) - t0 )) s ($(du -h "$log" | cut -f1))" >&2
fi
t0=$(date +%s)
# the clouds and images stay out of outputs.lcmlog (the maps are files): a 30 min log would
# otherwise need another ~15 GB
"$root/scripts/run_pipeline.sh" --log "$log" --config "$config" --out "$out" \
  --record ODOMETRY,KEYFRAME,LOOP_CORRECTION,HEALTH,GROUND_TRUTH ${without[@]+"${without[@]}"} ${swap[@]+"${swap[@]}"} >&2
wall=$(( $(date +%s) - t0 ))
{
  echo "# Soak: $name, $duration s of sensor time"
  echo
  echo "pipeline wall time ${wall} s (lockstep, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))"
  echo
  "$bin/livo-report" memory "$out/outputs.lcmlog" --at "$at"
  echo
  for f in "$out"/evaluation_*.json; do
    [ -f "$f" ] || continue
    python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print('ATE', sys.argv[1].split('/')[-1], '%.4f m' % j['ate']['rmse'])" "$f"
  done
  for f in colour_map.ply global_map.ply; do
    [ -f "$out/$f" ] && echo "$f: $(head -c 400 "$out/$f" | grep -a -m1 'element vertex' | cut -d' ' -f3) points"
  done
  [ -f "$out/octomap.bt" ] && echo "octomap.bt: $(du -h "$out/octomap.bt" | cut -f1)"
} | tee "$out/soak.md"
}
