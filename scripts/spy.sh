#!/usr/bin/env bash
# Starts lcm-spy with Traverse's message types on its class path, so that every channel decodes:
#
#   scripts/spy.sh [--lcm-url URL]
#   scripts/spy.sh --check     # no window: says how many of lcmtypes/*.lcm lcm-spy found
#
# URL: the graph's LCM URL (run-graph.sh prints it; default LCM_DEFAULT_URL, else LCM's own).
# Needs the Java types (build/java/traverse-lcmtypes.jar, built when a JDK and liblcm-java are
# installed: scripts/setup.sh installs both). Debian's lcm-spy script passes -Xincgc, which Java 17
# refuses; this runs the same class (lcm.spy.Spy) without it.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
url="" check=""
while (($#)); do
  case "$1" in
    --check) check=1; shift ;;
    --lcm-url) url="${2:?--lcm-url needs a URL}"; shift 2 ;;
    --lcm-url=*) url="${1#*=}"; shift ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "spy.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
jar="$ROOT/build/java/traverse-lcmtypes.jar"
lcm_jar=/usr/share/java/lcm.jar
[[ -f $lcm_jar ]] || { echo "spy.sh: $lcm_jar missing (apt-get install liblcm-java)" >&2; exit 1; }
[[ -f $jar ]] || { echo "spy.sh: $jar missing (build with a JDK installed: scripts/setup.sh)" >&2; exit 1; }
cp="$lcm_jar:$jar"
[[ -f /usr/share/java/jchart2d.jar ]] || { echo "spy.sh: jchart2d.jar missing (apt-get install libjchart2d-java)" >&2; exit 1; }
cp="$cp:/usr/share/java/jchart2d.jar"
if [[ -n $check ]]; then
  # Headless, lcm-spy lists the types it found on its class path, then cannot open its window.
  want=$(find "$ROOT/lcmtypes" -name '*.lcm' | wc -l)
  found=$(java -Djava.awt.headless=true -cp "$cp" lcm.spy.Spy 2>&1 | sed -n 's/^Found \([0-9]*\) LCM types$/\1/p' || true)
  echo "lcm-spy found ${found:-no} LCM types; lcmtypes/ has $want"
  [[ $found == "$want" ]]
  exit
fi
exec java -Djava.net.preferIPv4Stack=true -Xmx256m -ea -cp "$cp" lcm.spy.Spy ${url:+--lcm-url="$url"}
