#!/usr/bin/env bash
# Inside scripts/private_bus.sh. Lockstep replay through two chained consumers twice must give
# byte-identical outputs; a consumer that crashes or exits must end the replay with an error
# naming it, never a hang; a message lost on the bus is reported within seconds and the replay
# finishes without it.
set -uo pipefail
bin="$1"
dir=$(mktemp -d /tmp/livo-lockstep.XXXXXX)
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
playback_args=(--quiet)

"$bin/test-playback-log-writer" "$dir/in.lcmlog" 10 || fail "cannot write the input log"

run() {  # run OUT [stage1 die args...]
  local out="$1"; shift
  # the recorder is a lockstep consumer too: nothing reaches the log before it listens, and a
  # message it did not get is reported like any other loss (an lcm-logger started with a sleep
  # raced the replay on a loaded machine)
  env -u LIVO_TEST_DROP_RECEIVED "$bin/livo-record" --out "$out" --channels STAGE1,STAGE2 --name record 2>"$out.record.err" & local logger=$!
  "$bin/test-lockstep-consumer" stage1 "$@" & local s1=$!
  "$bin/test-lockstep-consumer" stage2 & local s2=$!
  timeout 120 "$bin/livo-playback" "$dir/in.lcmlog" --lockstep --consumers stage1,stage2,record --stall-timeout 3 \
    ${playback_args[@]+"${playback_args[@]}"} 2>"$out.err"
  local rc=$?
  sleep 0.3
  kill -INT $s1 $s2 2>/dev/null; wait $s1 $s2 2>/dev/null
  kill -INT $logger; wait $logger 2>/dev/null
  return $rc
}

run "$dir/a.lcmlog" || { cat "$dir/a.lcmlog.err"; fail "first lockstep replay failed"; }
run "$dir/b.lcmlog" || { cat "$dir/b.lcmlog.err"; fail "second lockstep replay failed"; }
"$bin/livo-loginfo" --digest "$dir/a.lcmlog" | grep '^STAGE' > "$dir/a.txt"
"$bin/livo-loginfo" --digest "$dir/b.lcmlog" | grep '^STAGE' > "$dir/b.txt"
cat "$dir/a.txt"
grep -Eq '^STAGE1 +livo\.pose_t +1000 ' "$dir/a.txt" || fail "STAGE1 should hold 1000 messages"
grep -Eq '^STAGE2 +livo\.pose_t +1000 ' "$dir/a.txt" || fail "STAGE2 should hold 1000 messages"
# the digest column must match (rates come from the logger's wall clock and may differ)
digests() { grep -o '^STAGE[12] .*' "$1" | awk '{print $1, $3}' | paste -d' ' - <(grep -o '[0-9a-f]\{16\}' "$1"); }
diff <(digests "$dir/a.txt") <(digests "$dir/b.txt") \
  || fail "two lockstep replays gave different outputs"
echo "lockstep replays identical"

run "$dir/crash.lcmlog" crash 50 && fail "playback succeeded although stage1 crashed"
grep -q "stage1" "$dir/crash.lcmlog.err" || { cat "$dir/crash.lcmlog.err"; fail "the crash report does not name stage1"; }
echo "crash reported: $(cat "$dir/crash.lcmlog.err")"

run "$dir/exit.lcmlog" exit 50 && fail "playback succeeded although stage1 exited"
grep -q "consumer stage1 exited" "$dir/exit.lcmlog.err" || { cat "$dir/exit.lcmlog.err"; fail "the exit report does not name stage1"; }
echo "exit reported: $(cat "$dir/exit.lcmlog.err")"

timeout 60 "$bin/livo-playback" "$dir/in.lcmlog" --lockstep --consumers nobody --startup-timeout 2 --quiet 2>"$dir/none.err" \
  && fail "playback succeeded with a consumer that never came"
echo "missing consumer reported: $(cat "$dir/none.err")"

# stage2 never receives the 500th STAGE1 (the node's test hook drops it on arrival, as a full UDP
# receive buffer would): lockstep names the loss within seconds, goes on, and finishes.
start=$(date +%s)
playback_args=(--loss-grace 1)
LIVO_TEST_DROP_RECEIVED=STAGE1:500 run "$dir/lost.lcmlog" || { cat "$dir/lost.lcmlog.err"; fail "the replay with a lost message failed"; }
took=$(( $(date +%s) - start ))
grep -q "lost on the bus: stage2 never received 1 STAGE1 message" "$dir/lost.lcmlog.err" \
  || { cat "$dir/lost.lcmlog.err"; fail "the loss was not reported"; }
grep -Eq "messages, [0-9.]+ s of log in [0-9.]+ s, 1 lost on the bus" "$dir/lost.lcmlog.err" || { cat "$dir/lost.lcmlog.err"; fail "the summary does not count the loss"; }
[ "$took" -lt 60 ] || fail "the replay with a lost message took $took s"
"$bin/livo-loginfo" "$dir/lost.lcmlog" | grep -Eq '^STAGE2 +livo\.pose_t +1000 ' || fail "STAGE2 should still hold 1000 messages"
echo "loss reported in a ${took} s replay: $(grep 'lost on the bus' "$dir/lost.lcmlog.err" | head -n 1)"
