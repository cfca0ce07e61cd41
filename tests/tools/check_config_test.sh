#!/usr/bin/env bash
# Every process that reads a project config, with --check-config, on every shipped config
# (config/rigs/*.yaml, config/sim/*.yaml). A process must accept a file unless the rig lacks the
# sensor it needs, and then refuse it, exit 1 as a normal start would, and name that sensor.
# What each process needs, from its config reader:
#   lio          rig.lidar (readLioNodeOptions: rig.section("lidar"), T_I_L required)
#   lio-graph    rig.lidar (readLioGraphNodeOptions)
#   vio          rig.camera (readVioNodeOptions)
#   vio-feature  rig.camera (readVioFeatureNodeOptions)
#   colour       rig.camera (readColourRig)
#   loop         nothing from the rig (readLoopNodeOptions reads loop: only)
#   octomap      nothing it cannot do without (T_I_L is identity without a LiDAR)
# Also: a file with a process's section (scripts/run_pipeline.sh starts that process) has what
# that process needs, and every template in config/rigs/ has a camera. LCM is never touched: each
# call gets an LCM URL no provider opens.
#
#   tests/tools/check_config_test.sh REPO_ROOT BIN_DIR
set -uo pipefail
root="$1"
bin="$2"

processes=(lio lio-graph vio vio-feature colour loop octomap)
declare -A needs=([lio]=lidar [lio-graph]=lidar [vio]=camera [vio-feature]=camera [colour]=camera [loop]="" [octomap]="")
declare -A section=([lio]=lio [lio-graph]=lio_graph [vio]=vio [vio-feature]=vio_feature [colour]=colour [loop]=loop
                    [octomap]=octomap)

# Whether FILE's rig: section holds SENSOR (a block key two spaces in, as every config writes it).
rig_has() {
  awk -v key="$2" '/^[^[:space:]#]/ { in_rig = /^rig:/ } in_rig && $0 ~ "^  " key ":" { found = 1 }
                   END { exit !found }' "$1"
}

failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

files=("$root"/config/rigs/*.yaml "$root"/config/sim/*.yaml)
work=$(mktemp -d /tmp/livo-check-config.XXXXXX)
trap 'rm -rf "$work"' EXIT

# Run every check first, two at a time (each start of an OpenCV-linked process loads ~150 shared
# libraries, about 0.1 s): the output and exit status of check i go to $work/i.out and $work/i.rc.
i=0
for file in "${files[@]}"; do
  for p in "${processes[@]}"; do
    ("$bin/livo-$p" --config "$file" --check-config --lcm-url nosuch:// >"$work/$i.out" 2>&1; echo $? >"$work/$i.rc") &
    i=$((i + 1))
    [ $((i % 2)) -eq 0 ] && wait
  done
done
wait

i=0
for file in "${files[@]}"; do
  name="${file#"$root"/}"
  declare -A has=([lidar]=0 [camera]=0)
  for sensor in lidar camera; do rig_has "$file" "$sensor" && has[$sensor]=1; done
  case "$(basename "$file")" in
    template_*) [ "${has[camera]}" = 1 ] || fail "$name: a template without a camera (every template has one)" ;;
  esac
  for p in "${processes[@]}"; do
    need="${needs[$p]}"
    out=$(cat "$work/$i.out")
    rc=$(cat "$work/$i.rc")
    i=$((i + 1))
    if [ -z "$need" ] || [ "${has[$need]}" = 1 ]; then
      if [ "$rc" -ne 0 ]; then
        fail "livo-$p refused $name (exit $rc): $(echo "$out" | grep "livo-$p:" | tail -1)"
      elif ! grep -qxF "livo-$p: $file: valid (--check-config: not started)" <<<"$out"; then
        fail "livo-$p accepted $name but did not say so"
      fi
    else
      if grep -Eq "^${section[$p]}:" "$file"; then
        fail "$name has a ${section[$p]}: section, so run_pipeline.sh starts livo-$p, but its rig has no $need"
      fi
      if [ "$rc" -ne 1 ]; then
        fail "livo-$p on $name, whose rig has no $need: exit $rc, expected 1 (a config error)"
      elif ! grep -q "^livo-$p: $file: rig.*$need" <<<"$out"; then
        fail "livo-$p on $name, whose rig has no $need: the message does not name it: $(echo "$out" | tail -1)"
      fi
    fi
  done
done

echo "$i checks (${#files[@]} configs x ${#processes[@]} processes), $failures failed"
[ $failures -eq 0 ]
