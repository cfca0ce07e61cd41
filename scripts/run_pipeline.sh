#!/usr/bin/env bash
# Runs a recorded log through the pipeline on a private LCM bus and writes, into --out:
#   outputs.lcmlog   every output channel (and GROUND_TRUTH), recorded by livo-record, which takes
#                    part in lockstep so nothing is missed (lcm-logger cannot say it is ready)
#   odometry.tum     the online estimate (body pose at every scan)
#   trajectory.tum   the final estimate (loop-corrected when loop closure ran)
#   timing.json      per process: messages, median/p90/max ms, peak RSS
#   evaluation_*.json, *.svg   accuracy against GROUND_TRUTH, if the log has it
#   report.md        all of it for a person; logs/<process>.log: what each process printed
#   maps and other files the processes write (they run in DIR)
#
#   scripts/run_pipeline.sh --log LOG --config FILE --out DIR [--realtime] [--without P,...]
#                           [--swap P=EXE] [--processes P,...] [--record CH,CH,...]
#                           [--faults F,...] [--seed N]   (livo-playback fault injection)
# Processes default to those of lio, vio, loop, colour, octomap that have a section in FILE.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$(cd "${LIVO_BUILD_DIR:-$root/build}" 2>/dev/null && pwd)/bin" || bin="$root/build/bin"
all_processes=(lio vio loop colour octomap)

usage() { sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "run_pipeline.sh: $*" >&2; exit 1; }

log="" config="" out="" realtime=0 without="" processes="" inside=0 faults="" seed=1
record='ODOMETRY,REGISTERED_SCAN,KEYFRAME,LOOP_CORRECTION,COLORED_CLOUD,OCTOMAP,STATE_PRIOR,STATE_POSTERIOR,HEALTH,GROUND_TRUTH'
declare -A swap=()
while [ $# -gt 0 ]; do
  case "$1" in
    --log) log="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --realtime) realtime=1; shift ;;
    --without) without="$2"; shift 2 ;;
    --processes) processes="$2"; shift 2 ;;
    --record) record="$2"; shift 2 ;;
    --faults) faults="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --swap) [[ "$2" == *=* ]] || die "--swap takes PROCESS=EXECUTABLE"; swap["${2%%=*}"]="${2#*=}"; shift 2 ;;
    --inside-bus) inside=1; shift ;;
    -h|--help) usage 0 ;;
    *) echo "run_pipeline.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[ -n "$log" ] && [ -n "$config" ] && [ -n "$out" ] || usage
[ -f "$log" ] || die "no such log: $log"
[ -f "$config" ] || die "no such config: $config"
log="$(cd "$(dirname "$log")" && pwd)/$(basename "$log")"
config="$(cd "$(dirname "$config")" && pwd)/$(basename "$config")"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
for tool in livo-playback livo-record livo-report; do
  [ -x "$bin/$tool" ] || die "$bin/$tool missing: run scripts/build.sh"
done

# Which processes: --processes, else every known one with a section in the config.
if [ -z "$processes" ]; then
  for p in "${all_processes[@]}"; do
    grep -Eq "^$p:" "$config" && processes+="${processes:+,}$p"
  done
fi
for p in "${!swap[@]}"; do [[ ",$processes," == *",$p,"* ]] || processes+="${processes:+,}$p"; done
selected=()
IFS=, read -ra wanted <<<"$processes"
for p in "${wanted[@]}"; do
  [[ ",$without," == *",$p,"* ]] && continue
  selected+=("$p")
done
[ ${#selected[@]} -gt 0 ] || die "no process to run (none of ${all_processes[*]} has a section in $config, or all are --without)"
exe_of() { echo "${swap[$1]:-$bin/livo-$1}"; }
for p in "${selected[@]}"; do
  [ -x "$(exe_of "$p")" ] || die "no executable for process '$p': $(exe_of "$p") (not built yet? use --without $p)"
done

if [ "$inside" = 0 ]; then
  swaps=()
  for p in "${!swap[@]}"; do swaps+=(--swap "$p=${swap[$p]}"); done
  echo "run_pipeline.sh: ${selected[*]} on $(basename "$log") -> $out" >&2
  rc=0
  "$root/scripts/private_bus.sh" "$0" --inside-bus --log "$log" --config "$config" --out "$out" \
    --processes "$(IFS=,; echo "${selected[*]}")" --record "$record" ${swaps[@]+"${swaps[@]}"} \
    --faults "$faults" --seed "$seed" \
    $([ "$realtime" = 1 ] && echo --realtime) || rc=$?

  # Files for the user, whatever happened above (outputs so far are kept).
  warnings=()
  if [ -f "$out/outputs.lcmlog" ]; then
    "$bin/livo-report" extract "$out/outputs.lcmlog" --dir "$out" 2>>"$out/logs/report.log" \
      || warnings+=("no odometry was produced (see logs/)")
  else
    warnings+=("nothing was recorded")
  fi
  evaluations="" figures=""
  if [ -x "$bin/livo-evaluate" ] && [ -s "$out/odometry.tum" ] && \
     "$bin/livo-loginfo" "$log" | grep -q '^GROUND_TRUTH '; then
    for kind in odometry trajectory; do
      if "$bin/livo-evaluate" --est "$out/$kind.tum" --gt "$log:GROUND_TRUTH" --align se3 \
          --json "$out/evaluation_$kind.json" --plot "$out/$kind.svg" >"$out/logs/evaluate_$kind.txt" 2>&1; then
        evaluations+="${evaluations:+;}$kind=$out/evaluation_$kind.json"
        figures+="${figures:+;}$kind against ground truth=$kind.svg"
      else
        warnings+=("evaluation of $kind.tum failed: $(tail -n 1 "$out/logs/evaluate_$kind.txt")")
      fi
    done
  fi
  [ "$rc" = 0 ] || warnings+=("the run failed: $(tail -n 1 "$out/logs/run.txt" 2>/dev/null)")
  read -r log_s wall_s < "$out/logs/replay_times.txt" 2>/dev/null || { log_s=0; wall_s=0; }
  joined_warnings=$(IFS=';'; echo "${warnings[*]:-}")
  "$bin/livo-report" markdown --dir "$out" --log "$log" --config "$config" --processes "$(IFS=,; echo "${selected[*]}")" \
    --mode "$([ "$realtime" = 1 ] && echo 'real time' || echo lockstep)" --log-seconds "$log_s" --wall-seconds "$wall_s" \
    --evaluation "$evaluations" --figure "$figures" --warning "$joined_warnings" >/dev/null
  if [ "$rc" != 0 ]; then
    echo "run_pipeline.sh: FAILED (outputs so far kept in $out):" >&2
    cat "$out/logs/run.txt" >&2 || true
    exit "$rc"
  fi
  echo "$out/report.md"
  exit 0
fi

# ---- inside the private bus --------------------------------------------------------------------
exec 3>"$out/logs/run.txt"
"$bin/livo-record" --out "$out/outputs.lcmlog" --channels "$record" --name record 2>"$out/logs/record.log" &
logger=$!
declare -A pids=()
for p in "${selected[@]}"; do
  # in the output folder, so the files a process writes (maps, loops.json) land there
  (cd "$out" && exec "$(exe_of "$p")" --config "$config" --name "$p") >"$out/logs/$p.log" 2>&1 &
  pids[$p]=$!
done
cleanup() {
  for p in "${!pids[@]}"; do kill -INT "${pids[$p]}" 2>/dev/null || true; done
  kill -INT "$logger" 2>/dev/null || true
}
trap cleanup INT TERM

start=$(date +%s%N)
if [ "$realtime" = 1 ]; then
  replay=(--speed 1 --consumers "$(IFS=,; echo "${selected[*]}"),record" --startup-timeout 60)
else
  replay=(--lockstep --consumers "$(IFS=,; echo "${selected[*]}"),record" --stall-timeout 120 --startup-timeout 60)
fi
[ -n "$faults" ] && replay+=(--faults "$faults" --seed "$seed")
rc=0
"$bin/livo-playback" "$log" "${replay[@]}" 2> >(tee "$out/logs/playback.log" >&2) &
playback=$!
# A process that dies ends the replay at once (lockstep would otherwise wait for its stall timeout).
while kill -0 "$playback" 2>/dev/null; do
  for p in "${selected[@]}"; do
    if ! kill -0 "${pids[$p]}" 2>/dev/null; then
      echo "process $p died; stopping the replay" >>"$out/logs/playback.log"
      kill -INT "$playback" 2>/dev/null || true
      break 2
    fi
  done
  sleep 0.2
done
wait "$playback" || rc=$?
end=$(date +%s%N)
log_s=$(sed -n 's/.*messages, \([0-9.e+-]*\) s of log in.*/\1/p' "$out/logs/playback.log" | tail -n 1)
ms=$(( (end - start) / 1000000 ))
printf "%s %d.%03d\n" "${log_s:-0}" $((ms / 1000)) $((ms % 1000)) > "$out/logs/replay_times.txt"
[ "$rc" = 0 ] || echo "playback failed: $(tail -n 1 "$out/logs/playback.log")" >&3

# Stop the processes (they flush and send a final HEALTH), then the recorder.
failed=0
for p in "${selected[@]}"; do
  if ! kill -0 "${pids[$p]}" 2>/dev/null; then
    code=0; wait "${pids[$p]}" || code=$?
    echo "process $p died during the run (exit code $code); its last lines:" >&3
    tail -n 15 "$out/logs/$p.log" | sed 's/^/    /' >&3
    failed=1
    unset "pids[$p]"
  fi
done
for p in "${!pids[@]}"; do kill -INT "${pids[$p]}" 2>/dev/null || true; done
for p in "${!pids[@]}"; do
  for _ in $(seq 200); do kill -0 "${pids[$p]}" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "${pids[$p]}" 2>/dev/null; then
    echo "process $p did not stop within 20 s of SIGINT; killed" >&3
    kill -KILL "${pids[$p]}" 2>/dev/null || true
    failed=1
  fi
  code=0; wait "${pids[$p]}" || code=$?
  if [ "$code" != 0 ] && [ "$code" != 130 ]; then
    echo "process $p exited with code $code; its last lines:" >&3
    tail -n 15 "$out/logs/$p.log" | sed 's/^/    /' >&3
    failed=1
  fi
done
sleep 0.3
kill -INT "$logger" 2>/dev/null || true
wait "$logger" 2>/dev/null || true
[ "$rc" = 0 ] && [ "$failed" = 0 ] || exit 1
