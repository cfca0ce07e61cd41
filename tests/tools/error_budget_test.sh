#!/usr/bin/env bash
# scripts/error_budget.py on a few seconds of room_hard: each variant's overlay reaches the simulator
# and the rig (the truth file of exact_calibration has no calibration error, range_noise_1cm's
# config states 1 cm), budget.md has a row per variant, a second call reuses every run, and an
# unknown variant is refused.
set -uo pipefail
root="$1"; bin="$2"
dir=$(mktemp -d /tmp/livo-error-budget.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export LIVO_BUILD_DIR="$(dirname "$bin")"
run() { /usr/bin/python3 "$root/scripts/error_budget.py" --out "$dir/budget" --seeds 1 --duration 6 \
          --variants as_is,exact_calibration,range_noise_1cm "$@"; }
run >"$dir/first.txt" 2>"$dir/first.err" || { cat "$dir/first.txt" "$dir/first.err"; fail "error_budget.py failed"; }
grep -q "simulating" "$dir/first.err" || fail "the first call simulated nothing"
/usr/bin/python3 - "$dir/budget" <<'PY' || exit 1
import glob, json, sys
d = sys.argv[1]
rows = [l for l in open(d + '/budget.md') if l.startswith('| ') and not l.startswith('| variant') and not l.startswith('| ---')]
assert [r.split('|')[1].strip() for r in rows] == ['as_is', 'exact_calibration', 'range_noise_1cm'], rows
for r in rows:
    cells = [c.strip() for c in r.split('|')[2:-1]]
    assert all(c and 'nan' not in c for c in cells), r
exact = json.load(open(glob.glob(d + '/logs/room_hard__exact_calibration_s1_*.truth.json')[0]))['calibration_errors']
for sensor in ('lidar', 'camera'):
    assert all(v == 0 for v in exact[sensor]['rotation_vector'] + exact[sensor]['translation']), exact
    assert exact[sensor]['time_offset_s'] == 0, exact
drawn = json.load(open(glob.glob(d + '/logs/room_hard__as_is_s1_*.truth.json')[0]))['calibration_errors']
assert any(v != 0 for v in drawn['lidar']['rotation_vector']), drawn
noise = [l for l in open(d + '/configs/room_hard__range_noise_1cm.yaml') if 'range_noise_std' in l]
assert noise and all('0.01' in l for l in noise), noise
PY
run >"$dir/second.txt" 2>"$dir/second.err" || { cat "$dir/second.err"; fail "the second call failed"; }
[ ! -s "$dir/second.err" ] || { cat "$dir/second.err"; fail "the second call ran again what it had"; }
cmp -s "$dir/first.txt" "$dir/second.txt" || fail "the second call's table differs"
/usr/bin/python3 "$root/scripts/error_budget.py" --out "$dir/x" --variants as_is,no_such >"$dir/bad.txt" 2>&1 \
  && fail "an unknown variant was accepted"
grep -q "unknown variant no_such" "$dir/bad.txt" || { cat "$dir/bad.txt"; fail "no clear error for an unknown variant"; }
echo "error_budget.py: variants reach the simulator and the rig, runs reused"
