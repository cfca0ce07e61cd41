#!/usr/bin/env bash
# Runs a command on a private LCM bus: a network namespace of its own with `lo` up and multicast
# routed on it, and LCM_DEFAULT_URL pointing at that bus. Nothing reaches the host's network.
#
#   scripts/private_bus.sh CMD [ARGS...]
#
# Works as root (unshare --net) or as a user through an unprivileged user namespace
# (unshare --user --map-root-user --net). Inside an existing private bus it just runs CMD.
# LIVO_LCM_URL overrides the bus URL used inside (default below).
set -euo pipefail

if [ $# -eq 0 ] || [ "$1" = "--help" ] || [ "$1" = "-h" ]; then
  sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'
  [ $# -eq 0 ] && exit 2 || exit 0
fi

if [ "${LIVO_PRIVATE_BUS:-}" = "1" ]; then
  exec "$@"
fi

# ttl=0: never leaves the host even if routed; a large receive buffer for 1 MB point clouds
# Ask for what the kernel grants (2 x net.core.rmem_max), up to 16 MB, so LCM does not warn.
rmem_max=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 8388608)
buf=$((2 * rmem_max)); [ "$buf" -gt 16777216 ] && buf=16777216
url="${LIVO_LCM_URL:-udpm://239.255.76.67:7667?ttl=0&recv_buf_size=$buf}"

command -v unshare >/dev/null || { echo "private_bus.sh: 'unshare' (util-linux) is not installed" >&2; exit 1; }
command -v ip >/dev/null || { echo "private_bus.sh: 'ip' (iproute2) is not installed" >&2; exit 1; }

inner='
set -e
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo
# net.core.rmem_max is per network namespace on recent kernels; raise it where we may.
sysctl -q -w net.core.rmem_max=33554432 2>/dev/null || true
export LIVO_PRIVATE_BUS=1
export LCM_DEFAULT_URL="$LIVO_INNER_URL"
unset LIVO_INNER_URL
exec "$@"
'

export LIVO_INNER_URL="$url"
if [ "$(id -u)" -eq 0 ] && unshare --net true 2>/dev/null; then
  exec unshare --net -- bash -c "$inner" private_bus "$@"
elif unshare --user --map-root-user --net true 2>/dev/null; then
  exec unshare --user --map-root-user --net -- bash -c "$inner" private_bus "$@"
else
  cat >&2 <<'MSG'
private_bus.sh: cannot create a private network namespace.
  As root this needs CAP_SYS_ADMIN (unshare --net); as a user it needs unprivileged user
  namespaces (sysctl kernel.unprivileged_userns_clone=1, or user.max_user_namespaces > 0).
  Without either, run single processes on the in-process memq:// provider instead.
MSG
  exit 1
fi
