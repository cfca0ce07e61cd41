#!/usr/bin/env bash
# LiDAR-inertial-visual odometry through the real pipeline (livo-lio + livo-vio, the camera hand-off
# over LCM): on a 20 s simulated corridor (textured walls; with a 50 m LiDAR, degenerate along its axis) the
# LIVO ATE is at most 70 % of the LIO-only one; on an 8 s room it is no worse; every STATE_PRIOR is
# answered; two lockstep runs give byte-identical ODOMETRY.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-livo-pipeline.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"

ate() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['ate']['rmse'])" "$1/evaluation_odometry.json"; }

"$root/tests/pipeline/axis_degenerate_corridor.sh" "$root" "$dir/corridor.yaml" || fail "no corridor config"
for seq in corridor:20 room:8; do
  name=${seq%%:*} duration=${seq##*:}
  config="$root/config/sim/$name.yaml"
  [ "$name" = corridor ] && config="$dir/corridor.yaml"
  "$bin/livo-sim" --config "$config" --out "$dir/$name.lcmlog" --duration "$duration" --seed 2 --quiet \
    || fail "livo-sim $name failed"
  for run in livo livo_again lio; do
    procs=lio,vio
    [ "$run" = lio ] && procs=lio
    "$root/scripts/run_pipeline.sh" --log "$dir/$name.lcmlog" --config "$config" \
      --processes "$procs" --out "$dir/$name-$run" >/dev/null 2>"$dir/$name-$run.err" \
      || { cat "$dir/$name-$run.err"; fail "$name $run run failed"; }
  done
  livo=$(ate "$dir/$name-livo") lio=$(ate "$dir/$name-lio")
  handoff=$(grep "camera hand-off:" "$dir/$name-livo/logs/lio.log")
  echo "$name ${duration}s: ATE LIVO $livo m, LIO-only $lio m; $handoff"
  /usr/bin/python3 - "$name" "$livo" "$lio" "$handoff" <<'PY' || exit 1
import re, sys
name, livo, lio, handoff = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
priors, adopted, kept, missing = (int(re.search(r'(\d+) ' + w, handoff).group(1))
                                  for w in ('priors', 'posteriors adopted', 'kept the prior', 'unanswered'))
assert priors >= 10 * 8, handoff                 # 20 Hz images, all but the first second
assert adopted + kept == priors and missing == 0, handoff
assert adopted >= 0.9 * priors, handoff
if name == 'corridor':
    assert livo <= 0.7 * lio, (livo, lio)        # issue 7: at least 30 % lower where the LiDAR degenerates
else:
    assert livo <= lio * 1.05 + 1e-4, (livo, lio)  # and no worse where it does not
PY
done
a=$("$bin/livo-loginfo" --digest "$dir/corridor-livo/outputs.lcmlog" | grep '^ODOMETRY' | grep -o '[0-9a-f]\{16\}')
b=$("$bin/livo-loginfo" --digest "$dir/corridor-livo_again/outputs.lcmlog" | grep '^ODOMETRY' | grep -o '[0-9a-f]\{16\}')
[ -n "$a" ] && [ "$a" = "$b" ] || fail "two lockstep LIVO runs gave different ODOMETRY ($a vs $b)"
echo "two LIVO runs: identical ODOMETRY ($a)"
