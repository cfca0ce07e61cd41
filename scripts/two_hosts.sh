#!/usr/bin/env bash
# Runs two commands as on two machines of one LAN: a "base station" and a "robot", each in a network
# namespace of its own, joined by a veth pair (lan-base 10.76.67.2/24, lan-robot 10.76.67.1/24), the
# only link either has, with multicast routed on it and LCM_DEFAULT_URL a bus that crosses one hop
# (ttl=1), as between two hosts on one switch. Nothing reaches the host's network.
#
#   scripts/two_hosts.sh [--mtu N] --base CMD [ARGS...] --robot CMD [ARGS...]
#
# BASE starts first, ROBOT once the link is up on both ends. When ROBOT exits, BASE gets SIGTERM
# (scripts/run_pipeline.sh --no-playback stops its processes then) and is waited for; the link goes
# with BASE's namespace, so BASE should last until then. Exit status: ROBOT's if it failed, else
# BASE's. --mtu: the link's MTU (1500 by default, an Ethernet LAN's; LCM messages over it travel as
# IP fragments, as they would between hosts). LIVO_LCM_URL overrides the bus URL. Works as root or
# through an unprivileged user namespace, as scripts/private_bus.sh does.
set -euo pipefail

usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "two_hosts.sh: $*" >&2; exit 1; }

mtu=1500 base=() robot=() into=""
while [ $# -gt 0 ]; do
  case "$1" in
    --base) into=base; shift; continue ;;
    --robot) into=robot; shift; continue ;;
  esac
  if [ "$into" = base ]; then base+=("$1"); shift; continue; fi
  if [ "$into" = robot ]; then robot+=("$1"); shift; continue; fi
  case "$1" in
    --mtu) mtu="$2"; shift 2 ;;
    -h|--help) usage 0 ;;
    *) echo "two_hosts.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[ ${#base[@]} -gt 0 ] && [ ${#robot[@]} -gt 0 ] || usage
[[ "$mtu" =~ ^[0-9]+$ ]] && [ "$mtu" -ge 576 ] && [ "$mtu" -le 65535 ] || die "--mtu takes 576 to 65535"
command -v unshare >/dev/null || die "'unshare' (util-linux) is not installed"
command -v ip >/dev/null || die "'ip' (iproute2) is not installed"

# ttl=1: one hop, the link between the two namespaces (a router would not pass it on); the receive
# buffer as scripts/private_bus.sh asks for it (2 x net.core.rmem_max, up to 16 MB)
rmem_max=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 8388608)
buf=$((2 * rmem_max)); [ "$buf" -gt 16777216 ] && buf=16777216
export LIVO_TWO_HOSTS_URL="${LIVO_LCM_URL:-udpm://239.255.76.67:7667?ttl=1&recv_buf_size=$buf}"
export LIVO_TWO_HOSTS_MTU="$mtu"
sync_dir=$(mktemp -d /tmp/livo-two-hosts.XXXXXX)
export LIVO_TWO_HOSTS_SYNC="$sync_dir"
trap 'rm -rf "$sync_dir"' EXIT

# One end of the link, in the namespace this runs in: up, addressed, multicast routed on it; then a
# check that it is the namespace's only link besides lo (so nothing can reach the host's network).
# Sourced by both namespaces' scripts below.
configure='
configure_end() {  # NAME ADDRESS
  ip link set lo up
  ip link set "$1" mtu "$LIVO_TWO_HOSTS_MTU"
  ip addr add "$2/24" dev "$1"
  ip link set "$1" up
  ip route add 224.0.0.0/4 dev "$1"
  # net.core.rmem_max is per network namespace on recent kernels; raise it where we may
  sysctl -q -w net.core.rmem_max=33554432 2>/dev/null || true
  local links
  links=$(ip -o link show | awk -F": " "{ sub(/@.*/, \"\", \$2); print \$2 }" | sort | paste -sd" " -)
  [ "$links" = "$(printf "%s\n" lo "$1" | sort | paste -sd" " -)" ] ||
    { echo "two_hosts.sh: this namespace has the links $links, not just lo and $1" >&2; exit 1; }
  export LIVO_PRIVATE_BUS=1 LCM_DEFAULT_URL="$LIVO_TWO_HOSTS_URL"
}
wait_for() {  # FILE: another namespace got this far (10 s at most)
  for _ in $(seq 1000); do [ -e "$1" ] && return 0; sleep 0.01; done
  echo "two_hosts.sh: timed out waiting for $1" >&2; exit 1
}
'

# The base station: a namespace of its own inside the robot's, its end of the link moved in by PID.
base_script="$configure"'
set -e
: >"$LIVO_TWO_HOSTS_SYNC/base_ns"
wait_for "$LIVO_TWO_HOSTS_SYNC/moved"
configure_end lan-base 10.76.67.2
: >"$LIVO_TWO_HOSTS_SYNC/base_up"
exec "$@"
'

# The robot: the outer private namespace, holding the other end.
robot_script="$configure"'
set -e
nb=$1; shift
base=("${@:1:nb}"); robot=("${@:nb+1}")
ip link add lan-robot type veth peer name lan-base
unshare --net -- bash -c "$LIVO_TWO_HOSTS_BASE" base_station "${base[@]}" &
base_pid=$!
wait_for "$LIVO_TWO_HOSTS_SYNC/base_ns"
ip link set lan-base netns "$base_pid"
: >"$LIVO_TWO_HOSTS_SYNC/moved"
configure_end lan-robot 10.76.67.1
wait_for "$LIVO_TWO_HOSTS_SYNC/base_up"
robot_pid=""
trap "kill -TERM \$base_pid \$robot_pid 2>/dev/null || true" INT TERM
"${robot[@]}" &
robot_pid=$!
rc=0; wait "$robot_pid" || rc=$?
kill -TERM "$base_pid" 2>/dev/null || true
base_rc=0; wait "$base_pid" || base_rc=$?
[ "$rc" != 0 ] && exit "$rc"
exit "$base_rc"
'
export LIVO_TWO_HOSTS_BASE="$base_script"

if [ "$(id -u)" -eq 0 ] && unshare --net true 2>/dev/null; then
  unshare --net -- bash -c "$robot_script" robot "${#base[@]}" "${base[@]}" "${robot[@]}" &
elif unshare --user --map-root-user --net true 2>/dev/null; then
  unshare --user --map-root-user --net -- bash -c "$robot_script" robot "${#base[@]}" "${base[@]}" "${robot[@]}" &
else
  die "cannot create network namespaces (see scripts/private_bus.sh: as root this needs CAP_SYS_ADMIN, as a user unprivileged user namespaces)"
fi
outer=$!
trap 'kill -TERM "$outer" 2>/dev/null || true' INT TERM
rc=0; wait "$outer" || rc=$?
# a signal above interrupts the first wait: wait again for the namespaces to wind down
kill -0 "$outer" 2>/dev/null && { wait "$outer" || rc=$?; }
exit "$rc"
