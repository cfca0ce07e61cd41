#!/usr/bin/env bash
# Runs inside scripts/private_bus.sh: subscriber and publisher as two processes on the private bus.
set -euo pipefail
pub="$1"
sub="$2"
ready=$(mktemp -u /tmp/livo-bus-ready.XXXXXX)
trap 'rm -f "$ready"' EXIT
"$sub" "$ready" &
sub_pid=$!
"$pub" "$ready"
wait "$sub_pid"
