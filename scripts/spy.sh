#!/usr/bin/env bash
# Starts lcm-spy decoding every livo-lcm channel (Debian's lcm-spy wrapper is broken on Java 17,
# so this launches lcm.spy.Spy directly with lcm.jar, jchart2d.jar and build/livo_lcmtypes.jar).
#   scripts/spy.sh [--lcm-url URL]       inspect a bus (run it inside scripts/private_bus.sh to see a
#                                        private one: scripts/private_bus.sh bash -c 'CMD & scripts/spy.sh')
#   scripts/spy.sh --check               verify the classpath and the types without opening a window
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LIVO_BUILD_DIR:-$root/build}"
types_jar="$build/livo_lcmtypes.jar"
lcm_jar=/usr/share/java/lcm.jar
chart_jar=/usr/share/java/jchart2d.jar
for f in "$lcm_jar" "$chart_jar"; do
  [ -f "$f" ] || { echo "spy.sh: $f missing: run scripts/install_deps.sh (liblcm-java, libjchart2d-java)" >&2; exit 1; }
done
[ -f "$types_jar" ] || { echo "spy.sh: $types_jar missing: run scripts/build.sh (needs javac)" >&2; exit 1; }
command -v java >/dev/null || { echo "spy.sh: java not found: run scripts/install_deps.sh" >&2; exit 1; }
cp="$lcm_jar:$chart_jar:$types_jar"

if [ "${1:-}" = "--check" ]; then
  command -v javap >/dev/null || { echo "spy.sh: javap (JDK) not found" >&2; exit 1; }
  javap -cp "$cp" lcm.spy.Spy >/dev/null
  n=0
  for lcm_file in "$root"/lcmtypes/*.lcm; do
    t=$(basename "$lcm_file" .lcm)
    javap -cp "$cp" "livo.$t" | grep -q "LCM_FINGERPRINT" || { echo "spy.sh: livo.$t missing from $types_jar" >&2; exit 1; }
    n=$((n + 1))
  done
  echo "spy.sh: lcm.spy.Spy and $n livo types on the classpath: $cp"
  exit 0
fi

exec java -server -Djava.net.preferIPv4Stack=true -Xmx256m -ea -cp "$cp" lcm.spy.Spy "$@"
