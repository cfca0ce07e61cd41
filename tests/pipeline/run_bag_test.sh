#!/usr/bin/env bash
# scripts/run_bag.sh end to end on a bag this project did not simulate: tests/tools/make_vlp16_bag.py
# (python3-rosbag + numpy, written from scratch) makes 12 s of a VLP-16, a 200 Hz IMU, a 640x480
# colour camera with camera_info and ground truth, at the nominal values of
# config/rigs/template_velodyne_vlp16.yaml, which runs it unedited (issue 17: bag -> report with
# run_bag.sh and a config from config/rigs/, no file edited by hand). Checks: the import's counts,
# the starter rig's camera_info intrinsics, report.md's ATE against the bag's ground truth (under
# the bound below), odometry.tum, report.html if the build writes one. And run_bag.sh stops clearly
# on a missing bag, a missing rig, a rig that fails --check-config and a rig whose camera size
# differs from the bag's (both sizes named, before the pipeline starts).
#
#   tests/pipeline/run_bag_test.sh REPO_ROOT BIN_DIR
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-run-bag.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
template="$root/config/rigs/template_velodyne_vlp16.yaml"
ate_bound=0.03  # m, SE(3)-aligned RMSE of odometry.tum; measured 0.0030 (seed 2, 12 s)

start=$(date +%s)
/usr/bin/python3 "$root/tests/tools/make_vlp16_bag.py" "$dir/walk.bag" --duration 12 --seed 2 2>"$dir/gen.err" \
  || { cat "$dir/gen.err"; fail "make_vlp16_bag.py failed"; }
echo "bag: $(tail -n 1 "$dir/gen.err")"

# Clear refusals, each before any import or run.
expect_refusal() {  # NAME PATTERN... -- ARGS: run_bag.sh must exit 1 and print every pattern on stderr
  local name="$1"; shift
  local patterns=()
  while [ "$1" != "--" ]; do patterns+=("$1"); shift; done
  shift
  local rc=0
  "$root/scripts/run_bag.sh" "$@" >"$dir/$name.out" 2>"$dir/$name.err" || rc=$?
  [ "$rc" = 1 ] || { cat "$dir/$name.err"; fail "$name: exit $rc, expected 1"; }
  for p in "${patterns[@]}"; do
    grep -q -- "$p" "$dir/$name.err" || { cat "$dir/$name.err"; fail "$name: stderr does not say '$p'"; }
  done
  [ ! -s "$dir/$name.out" ] || fail "$name: printed a report path"
  echo "$name: refused: $(grep 'run_bag.sh:' "$dir/$name.err" | tail -n 1)"
}
expect_refusal missing_bag "no such bag: $dir/none.bag" -- "$dir/none.bag" --rig "$template" --out "$dir/x"
expect_refusal missing_rig "no such rig: $dir/none.yaml" -- "$dir/walk.bag" --rig "$dir/none.yaml" --out "$dir/x"
sed 's/^  camera_handoff:/  camera_handof:/' "$template" >"$dir/typo.yaml"  # a key no process reads
expect_refusal bad_rig "fails livo-lio --check-config" "camera_handof" -- "$dir/walk.bag" --rig "$dir/typo.yaml" --out "$dir/x"
sed 's/^\(    width:\) 640 /\1 752 /' "$template" >"$dir/wide.yaml"
expect_refusal wrong_size "752x480" "640x480" "does not fit the bag" -- \
  "$dir/walk.bag" --rig "$dir/wide.yaml" --ground-truth /ground_truth/pose --out "$dir/wide"
[ ! -e "$dir/wide/outputs.lcmlog" ] || fail "wrong_size: the pipeline ran"
grep -q "^    width: 640 .*measured" "$dir/wide/rig_from_bag.yaml" || fail "wrong_size: rig_from_bag.yaml lacks the bag's width"

# The bag through the whole pipeline with the template as it is.
"$root/scripts/run_bag.sh" "$dir/walk.bag" --rig "$template" --ground-truth /ground_truth/pose --out "$dir/run" \
  >"$dir/run.out" 2>"$dir/run.err" || { cat "$dir/run.err"; fail "run_bag.sh failed"; }
[ "$(head -n 1 "$dir/run.out")" = "$dir/run/report.md" ] || { cat "$dir/run.out"; fail "the first line is not report.md's path"; }
if [ -f "$dir/run/report.html" ]; then
  [ -s "$dir/run/report.html" ] || fail "report.html is empty"
  grep -qxF "$dir/run/report.html" "$dir/run.out" || fail "report.html exists but its path was not printed"
else
  grep -q "warning: no report.html" "$dir/run.err" || fail "no report.html and no warning about it"
fi
grep -q "rig check" "$dir/run.err" && { grep "rig check" "$dir/run.err"; fail "the template's nominal rig drew rig-check findings"; }
"$bin/livo-loginfo" "$dir/run/input.lcmlog" >"$dir/loginfo.txt"
/usr/bin/python3 - "$dir/run" "$dir/loginfo.txt" "$ate_bound" <<'PY' || exit 1
import json, sys
d, loginfo, bound = sys.argv[1], sys.argv[2], float(sys.argv[3])
counts = {l.split()[0]: int(l.split()[2]) for l in open(loginfo) if l.split() and l.split()[0].isupper() and len(l.split()) > 2
          and l.split()[2].isdigit()}
want = {'IMU': 2400, 'LIDAR': 120, 'CAMERA': 239, 'GROUND_TRUTH': 1200}
assert all(counts.get(k) == v for k, v in want.items()), ('import counts', counts)
rig = open(d + '/rig_from_bag.yaml').read()
for line in ('    fx: 500 ', '    cy: 239.5 ', '    model: VLP-16 ', '    rate_hz: 200 ', '    color: true '):
    assert line in rig, ('rig_from_bag.yaml lacks', line)
rows = [l.split() for l in open(d + '/odometry.tum') if l.strip() and not l.startswith('#')]
assert len(rows) >= 100 and all(len(r) == 8 for r in rows), ('odometry.tum', len(rows))
report = open(d + '/report.md').read()
row = [l for l in report.splitlines() if l.startswith('| odometry |')]
assert row, 'report.md has no accuracy row for the odometry'
ate = float(row[0].split('|')[2])
e = json.load(open(d + '/evaluation_odometry.json'))
assert abs(ate - e['ate']['rmse']) < 1e-4, (ate, e['ate'])
assert ate < bound, ('ATE %.4f m over the bound %.2f m' % (ate, bound))
t = json.load(open(d + '/timing.json'))
print('bag -> report: %d poses, ATE rmse %.4f m (bound %.2f), lio median %.1f ms per scan, vio %s images'
      % (len(rows), ate, bound, t['lio']['channels'].get('work:sweep', t['lio']['channels']['LIDAR'])['median_ms'],
         t.get('vio', {}).get('channels', {}).get('CAMERA', {}).get('messages', '-')))
PY
echo "whole test: $(( $(date +%s) - start )) s"
