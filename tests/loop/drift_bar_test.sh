#!/usr/bin/env bash
# The loop-closure drift bar end to end (issues 8 and 19; ctest label "slow": about 3 minutes on two
# cores): five simulated minutes of config/sim/campus_loop_long_hard.yaml (consumer IMU, calibration
# errors, a noisy LiDAR: the drift is the LIO's own, with its full 100 m map) through the pipeline
# with livo-loop and, if it published a correction, without; with loop closure the final keyframe
# trajectory's drift at the return to the start must be at most half the LIO's and its ATE at most
# the LIO's
# (tests/loop/drift_bar.py), no accepted loop may be false (tests/loop/check_loops.py), and the
# LIO's keyframe increments, which weight the graph's odometry edges, must not be overconfident
# against the truth (tests/loop/keyframe_nees.py: mean NEES at most the upper end of its 95 % band;
# 82.5 for 6 before the held calibration entered their covariance, 4.3 since: on the cautious side).
# The ATE bar was "no worse", then 1.5 times the LIO's while the graph weighted its odometry edges
# with a drift model (the LIO at 0.032 m, the keyframes at 0.047 m). With the LIO's own increment
# covariances, the correction gate against them, the loops' roll and pitch left to gravity priors
# and a last optimisation at exit (processes/loop/README.md) the keyframes are at 0.029 m (0.90 of
# the LIO's) with the drift at the return cut to 0.09 of it, so the bar is "no worse" again; with
# the held calibration in the increments' covariances 0.027 m (0.85), drift 0.09.
#   tests/loop/drift_bar_test.sh SOURCE_DIR BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-drift-bar.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
config="$root/config/sim/campus_loop_long_hard.yaml"
"$bin/livo-sim" --config "$config" --out "$dir/campus.lcmlog" --duration 300 --quiet || fail "livo-sim failed"
"$root/scripts/run_pipeline.sh" --log "$dir/campus.lcmlog" --config "$config" --out "$dir/loop" \
  >/dev/null 2>"$dir/loop.err" || { cat "$dir/loop.err"; fail "the run with loop closure failed"; }
# livo-lio hears nothing from livo-loop but its LOOP_CORRECTIONs: while none is published, its outputs
# are those of a run without livo-loop to the bit (lockstep replays are deterministic:
# Pipeline.FastLockstepEqualsSerial), so that run is made only when a correction was published.
corrections=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["corrections"])' \
  "$dir/loop/loops.json") || fail "loops.json unreadable"
if [ "$corrections" = 0 ]; then
  lio="$dir/loop"
  echo "no correction published: the LIO alone is this run's livo-lio"
else
  lio="$dir/lio"
  "$root/scripts/run_pipeline.sh" --log "$dir/campus.lcmlog" --config "$config" --out "$lio" --without loop \
    >/dev/null 2>"$dir/lio.err" || { cat "$dir/lio.err"; fail "the LIO-only run failed"; }
fi
grep -q '^- lio: wheel updates: [0-9]* accepted' "$lio/report.md" \
  || fail "report.md does not count the LIO's wheel updates (Sensor use)"
/usr/bin/python3 "$root/tests/loop/drift_bar.py" --log "$dir/campus.lcmlog" --lio-only "$lio" \
  --with-loop "$dir/loop" --bin "$bin" --max-ate-ratio 1.0 || fail "drift bar missed"
/usr/bin/python3 "$root/tests/loop/check_loops.py" --log "$dir/campus.lcmlog" --loops "$dir/loop/loops.json" \
  > "$dir/loops.txt" || { cat "$dir/loops.txt"; fail "false loops"; }
tail -n 1 "$dir/loops.txt"
/usr/bin/python3 "$root/tests/loop/keyframe_nees.py" --log "$dir/campus.lcmlog" --outputs "$lio/outputs.lcmlog" \
  --check-not-overconfident > "$dir/nees.txt" || { cat "$dir/nees.txt"; fail "the LIO's keyframe increments are overconfident"; }
head -n 1 "$dir/nees.txt"
