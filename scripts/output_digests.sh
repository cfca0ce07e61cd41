#!/usr/bin/env bash
# The pipeline's outputs as fingerprints, to show that a restructuring changed nothing (issue 45):
# the room and campus demos (scripts/demo.sh's sequences, seed 1) run in lockstep through every
# process, and 20 s of bridge_deck through the second paper's pair (livo-lio-graph swapped in for
# lio, coupled to livo-vio-feature: wheels, depth, visual_state); then per run each recorded
# channel's digest (livo-loginfo --digest; HEALTH and PROGRESS left out: they carry wall-clock
# timings) and the md5 of every map and trajectory file.
#
#   scripts/output_digests.sh --out DIR [--logs DIR] [--runs room:30,campus_loop:60,bridge_deck:20:paper2]
#                             [--against FILE]
#
# A run is NAME:SECONDS (every process of config/sim/NAME.yaml) or NAME:SECONDS:paper2 (the pair).
#
# Writes DIR/digests.txt ("RUN channel NAME DIGEST" and "RUN file NAME MD5" lines, sorted) and
# prints it. --against FILE compares with an earlier digests.txt: prints the lines that differ and
# exits 1 if any does. Logs are simulated into --logs (default DIR/logs) once and reused while their
# config is older than them. The binaries are $LIVO_BUILD_DIR/bin (default build/bin), as for
# run_pipeline.sh, so two builds compare side by side:
#   LIVO_BUILD_DIR=/tmp/before scripts/output_digests.sh --out /tmp/d0
#   scripts/output_digests.sh --out /tmp/d1 --logs /tmp/d0/logs --against /tmp/d0/digests.txt
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"

usage() { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "output_digests.sh: $*" >&2; exit 1; }

out="" logs="" runs="room:30,campus_loop:60,bridge_deck:20:paper2" against=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --logs) logs="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --against) against="$2"; shift 2 ;;
    -h|--help) usage 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done
[ -n "$out" ] || usage
[ -z "$against" ] || [ -f "$against" ] || die "--against: no file $against"
for b in livo-sim livo-loginfo; do [ -x "$build/bin/$b" ] || die "no $build/bin/$b (build first)"; done
logs="${logs:-$out/logs}"
mkdir -p "$out" "$logs"

# The files a run writes that hold the estimate (not the report's pictures, timings or HTML).
files=(odometry.tum trajectory.tum keyframes.tum loops.json calibration.csv calibration.yaml
       global_map.ply colour_map.ply colour_map.pcd octomap.bt octomap.ot)

lines="$out/digests.txt.part"
: >"$lines"
IFS=',' read -ra list <<<"$runs"
for r in "${list[@]}"; do
  IFS=':' read -r name duration kind <<<"$r"
  [[ "$duration" =~ ^[0-9]+$ ]] && [[ "${kind:-}" =~ ^(|paper2)$ ]] ||
    die "--runs: want NAME:SECONDS or NAME:SECONDS:paper2, got '$r'"
  config="$root/config/sim/$name.yaml"
  [ -f "$config" ] || die "--runs: no config $config"
  log="$logs/${name}_${duration}s.lcmlog"
  if [ ! -s "$log" ] || [ "$log" -ot "$config" ]; then
    echo "== simulating $duration s of $name -> $log" >&2
    "$build/bin/livo-sim" --config "$config" --out "$log" --duration "$duration" --seed 1 >"$log.sim.txt" 2>&1 ||
      { tail -n 20 "$log.sim.txt" >&2; die "livo-sim failed on $name"; }
  fi
  tag="${name}_${duration}s${kind:+_$kind}"
  run="$out/$tag"
  pipeline=(--log "$log" --config "$config" --out "$run")
  if [ "${kind:-}" = paper2 ]; then
    echo "lio_graph: {visual_state: true}" >"$out/paper2.overlay.yaml"
    pipeline+=(--processes lio,vio_feature --swap "lio=$build/bin/livo-lio-graph" --overlay "$out/paper2.overlay.yaml")
  fi
  echo "== $tag ($duration s): the pipeline -> $run" >&2
  "$root/scripts/run_pipeline.sh" "${pipeline[@]}" >"$run.log" 2>&1 ||
    { tail -n 20 "$run.log" >&2; die "run_pipeline.sh failed on $name (log: $run.log)"; }
  "$build/bin/livo-loginfo" --digest "$run/outputs.lcmlog" |
    awk -v run="$tag" '$1 != "HEALTH" && $1 != "PROGRESS" {
      for (i = 3; i <= NF; ++i) if (length($i) == 16 && $i ~ /^[0-9a-f]+$/) { print run, "channel", $1, $i; break } }' >>"$lines"
  for f in "${files[@]}"; do
    [ -f "$run/$f" ] && echo "$tag file $f $(md5sum <"$run/$f" | cut -d' ' -f1)" >>"$lines"
  done
done
sort "$lines" >"$out/digests.txt"
rm -f "$lines"
cat "$out/digests.txt"
if [ -n "$against" ]; then
  if diff <(sort "$against") "$out/digests.txt" >"$out/digests.diff"; then
    echo "output_digests.sh: every digest and md5 as in $against" >&2
  else
    echo "output_digests.sh: differs from $against:" >&2
    cat "$out/digests.diff" >&2
    exit 1
  fi
fi
