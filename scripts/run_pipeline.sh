#!/usr/bin/env bash
# Runs a recorded log through the pipeline on a private LCM bus and writes, into --out:
#   outputs.lcmlog   every output channel (and GROUND_TRUTH), recorded by livo-record, which takes
#                    part in lockstep so nothing is missed (lcm-logger cannot say it is ready)
#   odometry.tum     the online estimate (body pose at every scan)
#   trajectory.tum   the final estimate (loop-corrected when loop closure ran)
#   timing.json      per process: messages, median/p90/max ms, peak RSS; in real time also the
#                    latency of its outputs (from logs/arrivals.tsv and logs/<process>.trace.tsv)
#   weak_spots.json  degenerate and predicted sweeps, images the VIO did not use, loop closures
#   resets.json      odometry resets (new epochs; [] when there was none)
#   evaluation_*.json, odometry.svg, trajectory.svg   accuracy against GROUND_TRUTH, if the log has
#                    it (the figures mark the weak spots)
#   trajectory_top.svg  the trajectory from above with its weak spots (no ground truth needed)
#   map_top.png, map_oblique.png   the RGB map (colour_map.ply) from above and from the side
#   octomap_slice.png   the OctoMap's occupied voxels around the trajectory's height, from above
#   pictures.json    what livo-report pictures drew, and why it drew no more
#   report.md        all of it for a person (the pictures in its "Maps" section)
#   report.html      the same as one self-contained page, with the RGB map and the trajectory in 3D
#                    (three.js from libjs-three inlined; open it in any browser, no network needed)
#   logs/<process>.log: what each process printed (logs/report.log: livo-report's notes)
#   maps and other files the processes write (they run in DIR): colour_map.ply/.pcd, octomap.bt/.ot,
#                    keyframes.tum, loops.json, global_map.ply, ...
#
#   scripts/run_pipeline.sh --log LOG --config FILE --out DIR [--realtime] [--without P,...]
#                           [--swap P=EXE] [--processes P,...] [--record CH,CH,...]
#                           [--faults F,...] [--seed N]   (livo-playback fault injection)
#                           [--respawn | --no-respawn] [--max-restarts N] [--kill P:SIG:AT_S,...]
#                           [--stop-grace S] [--overlay FILE,...] [--max-lag N] [--serial] [--ground-map]
#                           [--bus URL] [--remote P,...] [--no-playback]   (across hosts: README, Across machines)
# Processes default to those of lio, vio, vio_feature, loop, colour, octomap that have a section in FILE.
# --respawn (the default with --realtime): a process that exits is restarted (at most
# --max-restarts times each, 3 by default, after 0.5, 1, 2, ... s); the rest go on; report.md lists
# every restart. Without it a process that dies stops the run. --kill P:SIG:AT_S sends SIG to
# process P once AT_S seconds of the log have been replayed (for supervision tests; log time, so a
# faster pipeline still meets it at the same point of the recording). At the end
# every process gets SIGINT and --stop-grace seconds (60) to write its files before SIGKILL.
# --overlay FILE,...: YAML files merged over the config in order (livo-config merge: maps key by
# key, other values replaced) into DIR/config.yaml, which every process then reads.
# lio writes DIR/calibration.csv and DIR/calibration.yaml (the rig as its filter estimated it, an
# overlay for --overlay) when the config says lio.output_dir: . (every shipped sim config does).
# --max-lag N (lockstep): colour, octomap and the recorder, whose outputs no estimator takes, may
# fall up to N messages (16; and 16 MB, livo-playback --max-lag-mb) behind the rest, so they run
# beside lio, vio and loop on the second core (livo-playback --lag); 0: they keep in step. --serial: every process handles every message
# before the next goes out (no lag, no quiet promises): slower, and the outputs are the same.
# --ground-map: records REGISTERED_SCAN whatever --record says, and evaluation_odometry.json gets the
# ground-map thickness of those scans against GROUND_TRUTH (livo-evaluate --ground-map).
# --bus URL: the LCM bus to run on (a LAN's, e.g. udpm://239.255.76.67:7667?ttl=1) instead of a
# private one. --remote P,...: processes (and `record`, the recorder) that another host runs on that
# bus: the replay waits for them as for its own, none is started here. --no-playback: another host
# replays; the processes (and the recorder) run here until SIGTERM, then stop as at a replay's end.
set -euo pipefail
# One brace group: bash reads all of it before running any of it, so editing this file during a
# long run (a 30 min soak) cannot break that run.
{
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$(cd "${LIVO_BUILD_DIR:-$root/build}" 2>/dev/null && pwd)/bin" || bin="$root/build/bin"
all_processes=(lio vio vio_feature loop colour octomap)

usage() { sed -n '2,50p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "run_pipeline.sh: $*" >&2; exit 1; }

log="" config="" out="" realtime=0 without="" processes="" inside=0 faults="" seed=1 respawn="" max_restarts=3 kills="" stop_grace=60 overlays="" max_lag=16 serial=0 ground_map=0 bus="" remote="" no_playback=0
record='ODOMETRY,REGISTERED_SCAN,KEYFRAME,LOOP_CORRECTION,COLORED_CLOUD,OCTOMAP,STATE_PRIOR,STATE_POSTERIOR,VISUAL_STATE,VISUAL_ODOMETRY,HEALTH,GROUND_TRUTH'
live=0
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
    --respawn) respawn=1; shift ;;
    --no-respawn) respawn=0; shift ;;
    --max-restarts) max_restarts="$2"; shift 2 ;;
    --kill) kills="$2"; shift 2 ;;
    --stop-grace) stop_grace="$2"; shift 2 ;;
    --overlay) overlays+="${overlays:+,}$2"; shift 2 ;;
    --max-lag) max_lag="$2"; shift 2 ;;
    --serial) serial=1; shift ;;
    --ground-map) ground_map=1; shift ;;
    --bus) bus="$2"; shift 2 ;;
    --remote) remote="$2"; shift 2 ;;
    --no-playback) no_playback=1; shift ;;
    # scripts/run_live.sh: --no-playback with no log, livo-sensor-watch as the stand-in (logs/sensor_gaps.tsv),
    # SIGINT as SIGTERM, the run in a session of its own (a Ctrl-C reaches this script alone, which stops it in order)
    --live) live=1; no_playback=1; realtime=1; shift ;;
    --swap) [[ "$2" == *=* ]] || die "--swap takes PROCESS=EXECUTABLE"
            exe="${2#*=}"
            # a path relative to where the script was called from (the processes run inside --out)
            [[ "$exe" == */* && "$exe" != /* ]] && exe="$PWD/$exe"
            swap["${2%%=*}"]="$exe"; shift 2 ;;
    --inside-bus) inside=1; shift ;;
    -h|--help) usage 0 ;;
    *) echo "run_pipeline.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
{ [ -n "$log" ] || [ "$live" = 1 ]; } && [ -n "$config" ] && [ -n "$out" ] || usage
[ -n "$respawn" ] || respawn=$realtime
[[ "$max_restarts" =~ ^[0-9]+$ ]] || die "--max-restarts takes a whole number"
[[ "$stop_grace" =~ ^[0-9]+$ ]] || die "--stop-grace takes whole seconds"
[[ "$max_lag" =~ ^[0-9]+$ ]] || die "--max-lag takes a whole number"
[ "$ground_map" = 0 ] || [[ ",$record," == *",REGISTERED_SCAN,"* ]] || record+=",REGISTERED_SCAN"
[ "$live" = 1 ] || [ -f "$log" ] || die "no such log: $log"
[ -f "$config" ] || die "no such config: $config"
[ "$live" = 1 ] || log="$(cd "$(dirname "$log")" && pwd)/$(basename "$log")"
config="$(cd "$(dirname "$config")" && pwd)/$(basename "$config")"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
for tool in "$([ "$live" = 1 ] && echo livo-sensor-watch || echo livo-playback)" livo-record livo-report; do
  [ -x "$bin/$tool" ] || die "$bin/$tool missing: run scripts/build.sh"
done

# The config the processes read: the file with the overlays merged over it (outside the bus only;
# inside, --config is already the merged file).
if [ "$inside" = 0 ] && [ -n "$overlays" ]; then
  [ -x "$bin/livo-config" ] || die "$bin/livo-config missing: run scripts/build.sh"
  "$bin/livo-config" merge "$config" --overlay "$overlays" --out "$out/config.yaml" || die "cannot merge $overlays over $config"
  config="$out/config.yaml"
fi

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
exe_of() { echo "${swap[$1]:-$bin/livo-${1//_/-}}"; }  # process vio_feature: build/bin/livo-vio-feature
for p in "${selected[@]}"; do
  [ -x "$(exe_of "$p")" ] || die "no executable for process '$p': $(exe_of "$p") (not built yet? use --without $p)"
done

if [ "$inside" = 0 ]; then
  swaps=()
  for p in "${!swap[@]}"; do swaps+=(--swap "$p=${swap[$p]}"); done
  echo "run_pipeline.sh: ${selected[*]} on $([ "$live" = 1 ] && echo "the live bus ${bus:-${LCM_DEFAULT_URL:-}}" || basename "$log") -> $out" >&2
  # outputs.lcmlog records clouds: about as large as the input log (a full disk fails every process)
  free_mb=$(df -Pm "$out" | awk 'NR == 2 { print $4 }')
  log_mb=$(( $([ "$live" = 1 ] && echo 0 || stat -c %s "$log") / 1048576 ))
  [ "${free_mb:-0}" -ge $(( log_mb + 500 )) ] || \
    echo "run_pipeline.sh: warning: $free_mb MB free where $out is; the outputs may need about $log_mb MB and more" >&2
  rc=0
  # on a given bus (another host's processes share it) rather than a private one
  [ -z "$bus" ] || export LIVO_PRIVATE_BUS=1 LCM_DEFAULT_URL="$bus"
  inner=("$root/scripts/private_bus.sh" "$0" --inside-bus --log "$log" --config "$config" --out "$out" \
    --processes "$(IFS=,; echo "${selected[*]}")" --record "$record" ${swaps[@]+"${swaps[@]}"} \
    --remote "$remote" $([ "$no_playback" = 1 ] && echo --no-playback) \
    --faults "$faults" --seed "$seed" --max-restarts "$max_restarts" --max-lag "$max_lag" $([ "$serial" = 1 ] && echo --serial) --kill "$kills" --stop-grace "$stop_grace" \
    $([ "$respawn" = 1 ] && echo --respawn || echo --no-respawn) \
    $([ "$realtime" = 1 ] && echo --realtime) $([ "$live" = 1 ] && echo --live)) || true  # (an assignment fails as its last $(...))
  if [ "$no_playback" = 1 ]; then  # SIGTERM ends the run: passed on to the processes' side
    $([ "$live" = 1 ] && echo setsid -w) "${inner[@]}" &
    inner_pid=$!
    trap 'kill -TERM "$inner_pid" 2>/dev/null || true' TERM $([ "$live" = 1 ] && echo INT)
    wait "$inner_pid" || rc=$?
    kill -0 "$inner_pid" 2>/dev/null && { rc=0; wait "$inner_pid" || rc=$?; }  # the signal ended the first wait
    trap - TERM
  else
    "${inner[@]}" || rc=$?
  fi
  if [[ ",$remote," == *",record,"* ]]; then  # no outputs here: the recorder's host has them and the report
    [ "$rc" = 0 ] || { echo "run_pipeline.sh: FAILED:" >&2; cat "$out/logs/run.txt" >&2 || true; }
    exit "$rc"
  fi

  # Files for the user, whatever happened above (outputs so far are kept).
  warnings=()
  if [ -f "$out/outputs.lcmlog" ]; then
    extract_rc=0
    # real time: each output's latency into timing.json (the arrival and trace files of the run)
    latency=()
    [ -s "$out/logs/arrivals.tsv" ] && latency=(--arrivals "$out/logs/arrivals.tsv" --traces "$out/logs")
    "$bin/livo-report" extract "$out/outputs.lcmlog" --dir "$out" ${latency[@]+"${latency[@]}"} \
      2>"$out/logs/report_extract.log" || extract_rc=$?
    cat "$out/logs/report_extract.log" >>"$out/logs/report.log"
    [ "$extract_rc" = 0 ] || warnings+=("no odometry was produced (see logs/)")
    # what extract found wrong in the outputs (a trajectory it could not correct, undecodable messages)
    while IFS= read -r line; do warnings+=("${line#livo-report: warning: }"); done \
      < <(grep -E '^livo-report: warning: ' "$out/logs/report_extract.log" || true)
    rm -f "$out/logs/report_extract.log"
  else
    warnings+=("nothing was recorded")
  fi
  evaluations="" figures=""
  if [ -x "$bin/livo-evaluate" ] && [ -s "$out/odometry.tum" ] && \
     "$bin/livo-loginfo" "$([ "$live" = 1 ] && echo "$out/outputs.lcmlog" || echo "$log")" | grep -q '^GROUND_TRUTH '; then
    # the ground truth as replayed (recorded beside the outputs) when there is one: with --faults
    # that shift time (jump) it carries the same stamps the estimators saw
    gt="$log:GROUND_TRUTH"
    "$bin/livo-loginfo" "$out/outputs.lcmlog" 2>/dev/null | grep -q '^GROUND_TRUTH ' && gt="$out/outputs.lcmlog:GROUND_TRUTH"
    marks=()
    [ -s "$out/weak_spots.json" ] && marks=(--marks "$out/weak_spots.json")
    # the ground map of the odometry's own scans (the loop-corrected trajectory did not register them)
    ground=()
    if [ "$ground_map" = 1 ]; then
      if "$bin/livo-loginfo" "$out/outputs.lcmlog" 2>/dev/null | grep -q '^REGISTERED_SCAN '; then
        ground=(--ground-map "$out/outputs.lcmlog:REGISTERED_SCAN")
      else
        warnings+=("no REGISTERED_SCAN was recorded: no ground-map thickness")
      fi
    fi
    for kind in odometry trajectory; do
      extra=()
      [ "$kind" = odometry ] && extra=(${ground[@]+"${ground[@]}"})
      if "$bin/livo-evaluate" --est "$out/$kind.tum" --gt "$gt" --align se3 ${marks[@]+"${marks[@]}"} ${extra[@]+"${extra[@]}"} \
          --json "$out/evaluation_$kind.json" --plot "$out/$kind.svg" >"$out/logs/evaluate_$kind.txt" 2>&1; then
        evaluations+="${evaluations:+;}$kind=$out/evaluation_$kind.json"
        figures+="${figures:+;}$kind against ground truth=$kind.svg"
      else
        warnings+=("evaluation of $kind.tum failed: $(tail -n 1 "$out/logs/evaluate_$kind.txt")")
      fi
    done
  fi
  # Pictures of the maps and the trajectory for report.md's "Maps" section: a map the run did not
  # make is a note there; a failure here only a warning.
  rm -f "$out/pictures.json"
  "$bin/livo-report" pictures --dir "$out" >/dev/null 2>>"$out/logs/report.log" \
    || warnings+=("livo-report pictures failed (no Maps section): $(tail -n 1 "$out/logs/report.log")")
  [ "$rc" = 0 ] || warnings+=("the run failed: $(tail -n 1 "$out/logs/run.txt" 2>/dev/null)")
  while IFS= read -r line; do warnings+=("$line"); done < <(grep -E '^--kill .* was never sent' "$out/logs/run.txt" 2>/dev/null || true)
  # What the replay saw go wrong on the bus (messages lost, consumers away and back).
  while IFS= read -r line; do warnings+=("playback: ${line#*lockstep: }"); done \
    < <(grep -E '^\[playback\] lockstep: ' "$out/logs/playback.log" 2>/dev/null | grep -v 'restarted\|exited;\|silent for\|heard again\|may lag\|in step' || true)
  read -r log_s wall_s < "$out/logs/replay_times.txt" 2>/dev/null || { log_s=0; wall_s=0; }
  # live: the sensor time the odometry spans
  [ "$live" = 1 ] && log_s=$(awk '!/^#/ { if (!n++) a = $1; b = $1 } END { printf "%.3f", n ? b - a : 0 }' "$out/odometry.tum" 2>/dev/null || echo 0)
  joined_warnings=$(IFS=';'; echo "${warnings[*]:-}")
  injected=$(sed -n 's/^\[playback\] faults on \(.*\)$/\1/p' "$out/logs/playback.log" 2>/dev/null | paste -sd';' -)
  # the LIO's last word on its wheel updates (accepted, rejected, learned scales)
  sensor_use=$(grep -ho 'wheel updates: .*' "$out/logs/lio.log" 2>/dev/null | tail -n 1 | sed 's/^/lio: /; s/;/,/g' || true)
  "$bin/livo-report" markdown --dir "$out" --log "${log:-live bus ${bus:-${LCM_DEFAULT_URL:-}}}" --config "$config" --processes "$(IFS=,; echo "${selected[*]}")" \
    --mode "$([ "$live" = 1 ] && echo live || { [ "$realtime" = 1 ] && echo 'real time' || echo lockstep; })" --log-seconds "$log_s" --wall-seconds "$wall_s" \
    --evaluation "$evaluations" --figure "$figures" --warning "$joined_warnings" --injected "$injected" \
    --sensor-use "$sensor_use" \
    $([ "$respawn" = 1 ] && echo --restarts "$out/logs/restarts.tsv") \
    $([ "$live" = 1 ] && echo --sensor-gaps "$out/logs/sensor_gaps.tsv") >/dev/null
  # The same report as one page with the map in 3D; without it the run still has report.md.
  rm -f "$out/report.html"
  "$bin/livo-report" html --dir "$out" >/dev/null 2>>"$out/logs/report.log" \
    || echo "run_pipeline.sh: warning: report.html: $(grep -E '^livo-report( html)?: ' "$out/logs/report.log" | tail -n 1)" >&2
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
# Real time: when each message arrived and went out, for report.md's "Latency" (processes/report/
# README.md): the recorder times every message on the bus (livo-record --arrivals), each process
# its publications (LIVO_LATENCY_TRACE, common/node.hpp). None in lockstep (nothing changes there).
rm -f "$out/logs/arrivals.tsv" "$out/logs/"*.trace.tsv
if [ "$realtime" = 1 ]; then export LIVO_RECORD_ARRIVALS="$out/logs/arrivals.tsv"; fi
latency_trace() { if [ "$realtime" = 1 ]; then echo "$out/logs/$1.trace.tsv"; fi; }
# Lockstep with lagging sinks: their handler threads run niced (LIVO_HANDLER_NICE), so that the
# processes on the replay's critical path (playback, lio, vio, loop) get a core the moment they
# have work (scheduling, not order: the outputs are the same). Not their LCM receive threads: those
# keep draining the sockets, or the bus would overflow them while the sinks wait for a core.
sink_nice=()
[ "$realtime" = 0 ] && [ "$serial" = 0 ] && [ "$max_lag" -gt 0 ] && sink_nice=(env LIVO_HANDLER_NICE=10)
# Real time: the same, so that a pose or an image's answer never waits for a core behind the
# colouring or the OctoMap (report.md's "Latency"); the recorder's arrival times come from its
# receive thread, which keeps its priority.
[ "$realtime" = 1 ] && sink_nice=(env LIVO_HANDLER_NICE=10)
nice_of() { case "$1" in colour|octomap|record) echo "${sink_nice[@]}" ;; esac; }
logger=""  # the recorder, unless another host runs it (--remote record)
[[ ",$remote," == *",record,"* ]] ||
  { $(nice_of record) "$bin/livo-record" --out "$out/outputs.lcmlog" --channels "$record" --name record 2>"$out/logs/record.log" &
    logger=$!; }
: > "$out/logs/restarts.tsv"
declare -A pids=() restarts=() next_start=() died_at=() ended=()
now_ms() { echo $(( $(date +%s%N) / 1000000 )); }
start_process() {
  # in the output folder, so the files a process writes (maps, loops.json) land there; supervised,
  # a process may keep what must survive a restart in LIVO_STATE_DIR (lio: its epoch and keyframe
  # numbering), and LIVO_RESTARTS says how often it was restarted
  if [ "$respawn" = 1 ]; then
    (cd "$out" && LIVO_STATE_DIR="$out/state" LIVO_RESTARTS="${restarts[$1]:-0}" LIVO_LATENCY_TRACE="$(latency_trace "$1")" \
      exec $(nice_of "$1") "$(exe_of "$1")" \
      --config "$config" --name "$1") >>"$out/logs/$1.log" 2>&1 &
  else
    (cd "$out" && LIVO_LATENCY_TRACE="$(latency_trace "$1")" exec $(nice_of "$1") "$(exe_of "$1")" --config "$config" \
      --name "$1") >>"$out/logs/$1.log" 2>&1 &
  fi
  pids[$1]=$!
}
mkdir -p "$out/state"
for p in "${selected[@]}"; do restarts[$p]=0; start_process "$p"; done
cleanup() {
  for p in "${!pids[@]}"; do kill -INT "${pids[$p]}" 2>/dev/null || true; done
  kill -INT "$logger" 2>/dev/null || true
}
trap cleanup INT TERM
# What a restarted process starts without (processes/*/README.md, "Restarts").
lost_on_restart() {
  case "$1" in
    lio) echo "filter state and local map: re-initialised from the IMU; odometry goes on in a new epoch (frame), keyframe ids go on" ;;
    vio) echo "its patch map; lio ran LiDAR-only until it answered again" ;;
    loop) echo "keyframes and pose graph so far: no loops to places seen before the restart" ;;
    colour) echo "the coloured map so far (its files hold what it coloured after the restart)" ;;
    octomap) echo "the occupancy map so far (its files hold what it mapped after the restart)" ;;
    *) echo "its in-memory state" ;;
  esac
}
# the newest "[playback] X s of log" figure, for the restart table
log_time() { cat "$out/logs/log_clock" 2>/dev/null || echo '?'; }

start=$(date +%s%N)
# the replay's consumers: these processes, those of other hosts (--remote) and the recorder
consumers=("${selected[@]}")
IFS=, read -ra remote_list <<<"$remote"
for p in ${remote_list[@]+"${remote_list[@]}"}; do [ "$p" = record ] || consumers+=("$p"); done
consumers+=(record)
if [ "$realtime" = 1 ]; then
  replay=(--speed 1 --consumers "$(IFS=,; echo "${consumers[*]}")" --startup-timeout 60)
else
  replay=(--lockstep --consumers "$(IFS=,; echo "${consumers[*]}")" --stall-timeout 60 --startup-timeout 60)
  # the sinks (livo-playback checks from their PROGRESS that nothing but the recorder takes their outputs)
  lag=(record); for p in "${consumers[@]}"; do case "$p" in colour|octomap) lag+=("$p") ;; esac; done
  [ "$max_lag" -gt 0 ] && replay+=(--lag "$(IFS=,; echo "${lag[*]}")" --max-lag "$max_lag")
  [ "$serial" = 1 ] && replay+=(--serial)
  [ "$respawn" = 1 ] && replay+=(--respawn)
fi
[ -n "$faults" ] && replay+=(--faults "$faults" --seed "$seed")
rc=0
replay+=(--clock-file "$out/logs/log_clock")  # the log seconds replayed so far: --kill, the restart table
if [ "$live" = 1 ]; then  # the stand-in watches the sensors (warnings on stderr and logs/sensor_watch.log)
  echo "run_pipeline.sh: --live: no replay; the sensors' drivers publish on the bus" >"$out/logs/playback.log"
  "$bin/livo-sensor-watch" --config "$config" --out "$out/logs/sensor_gaps.tsv" 2> >(tee "$out/logs/sensor_watch.log" >&2) &
  playback=$!
  trap 'kill "$playback" 2>/dev/null || true' INT TERM
elif [ "$no_playback" = 1 ]; then  # another host replays: a stand-in that SIGTERM ends
  echo "run_pipeline.sh: --no-playback: another host replays; this one runs until SIGTERM" >"$out/logs/playback.log"
  sleep infinity &
  playback=$!
  trap 'kill "$playback" 2>/dev/null || true' INT TERM
else
  "$bin/livo-playback" "$log" "${replay[@]}" 2> >(tee "$out/logs/playback.log" >&2) &
  playback=$!
fi
t0=$(now_ms)
declare -a kill_plan=()
IFS=, read -ra kill_plan <<<"$kills"
# Supervision. Without --respawn a process that dies ends the replay at once (lockstep would
# otherwise wait for its stall timeout); with it, the process is restarted after a back-off.
while kill -0 "$playback" 2>/dev/null; do
  now=$(now_ms)
  clock=$(cat "$out/logs/log_clock" 2>/dev/null || true)
  for i in "${!kill_plan[@]}"; do  # --kill P:SIG:AT_S (log seconds, from playback's --clock-file)
    IFS=: read -r kp ksig kat <<<"${kill_plan[$i]}"
    if [ -n "$kp" ] && [ -n "${pids[$kp]:-}" ] && [ -n "$clock" ] && \
       [ "$(awk -v c="$clock" -v a="$kat" 'BEGIN { print (c >= a) }')" = 1 ]; then
      echo "run_pipeline.sh: --kill: SIG$ksig to $kp at $clock s of log" >>"$out/logs/playback.log"
      kill "-$ksig" "${pids[$kp]}" 2>/dev/null || true
      unset "kill_plan[$i]"
    fi
  done
  for p in "${selected[@]}"; do
    if [ -n "${next_start[$p]:-}" ]; then
      if [ "$now" -ge "${next_start[$p]}" ]; then
        restarts[$p]=$((restarts[$p] + 1))
        start_process "$p"
        unset "next_start[$p]"
        down=$(( now - died_at[$p] ))
        printf "%d.%03d\t%s\t%s\t%s\t%d\t%d.%03d\t%s\n" $(( (died_at[$p] - t0) / 1000 )) $(( (died_at[$p] - t0) % 1000 )) \
          "$(log_time)" "$p" "${ended[$p]}" "${restarts[$p]}" $((down / 1000)) $((down % 1000)) "$(lost_on_restart "$p")" \
          >>"$out/logs/restarts.tsv"
        echo "run_pipeline.sh: restarted $p (restart ${restarts[$p]} of at most $max_restarts)" >>"$out/logs/playback.log"
      fi
      continue
    fi
    [ -n "${pids[$p]:-}" ] || continue
    kill -0 "${pids[$p]}" 2>/dev/null && continue
    code=0; wait "${pids[$p]}" || code=$?
    unset "pids[$p]"
    if [ "$code" -gt 128 ]; then how="killed by SIG$(kill -l $((code - 128)) 2>/dev/null || echo $((code - 128)))"; else how="exited with code $code"; fi
    if [ "$respawn" != 1 ]; then
      echo "process $p died; stopping the replay" >>"$out/logs/playback.log"
      echo "process $p died during the run ($how); its last lines:" >&3
      tail -n 15 "$out/logs/$p.log" | sed 's/^/    /' >&3
      died=1
      kill -INT "$playback" 2>/dev/null || true
      [ "$no_playback" = 0 ] || kill "$playback" 2>/dev/null || true  # the stand-in ignores SIGINT
      break 2
    fi
    echo "=== $p $how; $( [ "${restarts[$p]}" -lt "$max_restarts" ] && echo restarting || echo 'not restarted: restart limit reached' ) ===" >>"$out/logs/$p.log"
    if [ "${restarts[$p]}" -lt "$max_restarts" ]; then
      died_at[$p]=$now
      ended[$p]=$how
      backoff=$(( 500 * (1 << restarts[$p]) )); [ "$backoff" -gt 8000 ] && backoff=8000
      next_start[$p]=$(( now + backoff ))
    else
      echo "process $p $how and reached the restart limit ($max_restarts); the run goes on without it" >&3
      printf "%s\t%s\t%s\t%s\t-\t-\t%s\n" "$(( (now - t0) / 1000 ))" "$(log_time)" "$p" "$how" "not restarted (limit of $max_restarts reached)" \
        >>"$out/logs/restarts.tsv"
      gave_up=1
    fi
  done
  # a kill to come is aimed within a few tenths of a log second even at 5x real time
  if [ ${#kill_plan[@]} -gt 0 ]; then sleep 0.05; else sleep 0.2; fi
done
wait "$playback" || rc=$?
[ "$no_playback" = 0 ] || rc=0
for k in "${kill_plan[@]}"; do
  echo "--kill $k was never sent: the replay ended at $(cat "$out/logs/log_clock" 2>/dev/null || echo '?') s of log" >&3
done
end=$(date +%s%N)
log_s=$(sed -n 's/.*messages, \([0-9.e+-]*\) s of log in.*/\1/p' "$out/logs/playback.log" | tail -n 1)
ms=$(( (end - start) / 1000000 ))
printf "%s %d.%03d\n" "${log_s:-0}" $((ms / 1000)) $((ms % 1000)) > "$out/logs/replay_times.txt"
[ "$rc" = 0 ] || echo "playback failed: $(tail -n 1 "$out/logs/playback.log")" >&3

# Stop the processes (they flush and send a final HEALTH), then the recorder.
failed=${died:-0}
for p in "${!pids[@]}"; do
  if ! kill -0 "${pids[$p]}" 2>/dev/null; then
    code=0; wait "${pids[$p]}" || code=$?
    if [ "$respawn" != 1 ]; then
      echo "process $p died during the run (exit code $code); its last lines:" >&3
      tail -n 15 "$out/logs/$p.log" | sed 's/^/    /' >&3
      failed=1
    fi
    unset "pids[$p]"
  fi
done
for p in "${!pids[@]}"; do kill -INT "${pids[$p]}" 2>/dev/null || true; done
for p in "${!pids[@]}"; do
  for _ in $(seq $((stop_grace * 10))); do kill -0 "${pids[$p]}" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "${pids[$p]}" 2>/dev/null; then
    echo "process $p did not stop within $stop_grace s of SIGINT; killed" >&3
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
if [ -n "$logger" ]; then
  kill -INT "$logger" 2>/dev/null || true
  wait "$logger" 2>/dev/null || true
fi
[ "$rc" = 0 ] && [ "$failed" = 0 ] || exit 1
exit 0
}
