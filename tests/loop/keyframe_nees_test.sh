#!/usr/bin/env bash
# The LIO's keyframe increments are as uncertain as their covariance says (issue 47): LIO-only 60 s
# runs of a seed nothing was tuned on, and the mean NEES of the increments between consecutive
# keyframes against the simulator's truth (tests/loop/keyframe_nees.py, the band of chi2(6 N) / N).
# - room and campus_loop: within the two-sided 95 % band, judged against the filter's part of the
#   covariance (the easy configs draw no calibration error). campus_loop was 10.1 on every seed
#   without the registration floor (overconfident), the room 3.8-4.7 with a residual sigma of 3 cm
#   (cautious); now 5.5-6.1 and 5.2-6.7 on seeds 802-806 (processes/lio/README.md).
# - room_hard: against all of the covariance (the held calibration included), mean NEES at most 12
#   (1.4x too sure in standard deviation). A band of one run cannot hold there: the calibration error
#   is drawn once per run, so a run's mean moves with its draw (3.4-7.5 on seeds 802-806, mean 5.6;
#   this seed 7.5 then, 5.85 at bb9c29b). The bound catches what the held calibration fixed (29-209
#   before it).
# The logs are made without images (livo-sim --no-images: the LIO alone gives the same outputs, in a
# quarter of the simulation time). campus_loop_hard is not run here (the costliest simulation):
# tests/loop/drift_bar_test.sh checks campus_loop_long_hard's increments the same one-sided way.
#   tests/loop/keyframe_nees_test.sh SOURCE_DIR BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-keyframe-nees.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
seed=${LIVO_NEES_SEED:-804}  # the floor and the residual sigma were tuned on 801
duration=60
status=0
for config in room campus_loop room_hard; do
  yaml="$root/config/sim/$config.yaml"
  "$bin/livo-sim" --config "$yaml" --out "$dir/$config.lcmlog" --duration "$duration" --seed "$seed" --no-images --quiet \
    || fail "$config: livo-sim failed"
  "$root/scripts/run_pipeline.sh" --log "$dir/$config.lcmlog" --config "$yaml" --processes lio --out "$dir/$config" \
    --record KEYFRAME,GROUND_TRUTH >/dev/null 2>"$dir/$config.err" || { cat "$dir/$config.err"; fail "$config: the LIO run failed"; }
  rm -f "$dir/$config.lcmlog"
  judged=(); case $config in *_hard) ;; *) judged=(--filter-only) ;; esac
  check=(--check); [ "$config" = room_hard ] && check=(--check-below 12)
  if /usr/bin/python3 "$root/tests/loop/keyframe_nees.py" --log "$dir/$config/outputs.lcmlog" \
       --outputs "$dir/$config/outputs.lcmlog" "${judged[@]}" "${check[@]}" > "$dir/$config.nees"; then
    echo "$config seed $seed: $(head -n 1 "$dir/$config.nees")"
  else
    cat "$dir/$config.nees"; echo "FAIL: $config seed $seed: mean NEES outside the bound (${check[*]})" >&2; status=1
  fi
  rm -rf "${dir:?}/$config"
done
exit $status
