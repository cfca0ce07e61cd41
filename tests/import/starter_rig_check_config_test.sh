#!/usr/bin/env bash
# livo-import --rig-out on three inputs: a bag with a LiDAR, an IMU and a camera with camera_info
# (camera_info.bag of make_test_bags.py), an EuRoC folder (camera and IMU, no LiDAR) and an Ouster
# capture (LiDAR and IMU, no camera). Each starter rig, unedited, passes the --check-config of every
# process unless its rig lacks the sensor that process needs (then it is refused and the file has no
# section for it, so scripts/run_pipeline.sh does not start it), as Tools.CheckConfigOfEveryRigAndSimConfig
# requires of the shipped configs; and it names at least one process to run.
#
#   tests/import/starter_rig_check_config_test.sh BIN_DIR BAGS_DIR SHARED_DATA_DIR
set -uo pipefail
bin="$1"; bags="$2"; data="$3"
dir=$(mktemp -d /tmp/livo-starter-rig.XXXXXX)
trap 'rm -rf "$dir"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

"$bin/livo-import" rosbag "$bags/camera_info.bag" --out "$dir/bag.lcmlog" --rig-out "$dir/bag.yaml" --quiet >/dev/null \
  || fail "import of camera_info.bag"
"$bin/livo-import" euroc "$data/euroc_v1_01" --out "$dir/euroc.lcmlog" --rig-out "$dir/euroc.yaml" --quiet >/dev/null \
  || fail "import of euroc_v1_01"
"$bin/livo-import" ouster "$data/ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap" --out "$dir/ouster.lcmlog" \
  --rig-out "$dir/ouster.yaml" --quiet >/dev/null || fail "import of the OS1-128 capture"

declare -A needs=([lio]=lidar [lio-graph]=lidar [vio]=camera [vio-feature]=camera [colour]=camera [loop]="" [octomap]="")
declare -A section=([lio]=lio [lio-graph]=lio_graph [vio]=vio [vio-feature]=vio_feature [colour]=colour [loop]=loop
                    [octomap]=octomap)
rig_has() { grep -q "^  $2:" "$1"; }
for name in bag euroc ouster; do
  file="$dir/$name.yaml"
  [ -s "$file" ] || { fail "no starter rig for $name"; continue; }
  runs=0
  for p in lio lio-graph vio vio-feature colour loop octomap; do
    out=$("$bin/livo-$p" --config "$file" --check-config --lcm-url nosuch:// 2>&1); rc=$?
    grep -Eq "^${section[$p]}:" "$file" && runs=$((runs + 1))
    need="${needs[$p]}"
    if [ -z "$need" ] || rig_has "$file" "$need"; then
      [ "$rc" = 0 ] || fail "livo-$p refuses the starter rig of $name: $(echo "$out" | tail -n 1)"
    else
      [ "$rc" = 1 ] || fail "livo-$p on the starter rig of $name (no $need): exit $rc, expected 1"
      grep -Eq "^${section[$p]}:" "$file" && fail "the starter rig of $name has a ${section[$p]}: section but no $need"
    fi
  done
  [ "$runs" -gt 0 ] || fail "the starter rig of $name has no pipeline section"
  echo "$name: $(grep -c 'REPLACE:' "$file") values to replace; sections: $(grep -E '^[a-z_]+:' "$file" | cut -d: -f1 | grep -v '^rig$' | paste -sd' ')"
done
grep -q "model: OS1-128 .*named by the input" "$dir/ouster.yaml" || fail "the Ouster starter does not name OS1-128 from the metadata"
grep -q "fx: 458.654 .*cam0/sensor.yaml" "$dir/euroc.yaml" || fail "the EuRoC starter does not take cam0's intrinsics"
[ $failures -eq 0 ]
