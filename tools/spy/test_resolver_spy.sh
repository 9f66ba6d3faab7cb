#!/usr/bin/env bash
# ctest spy_launcher: resolver-types.jar holds a class for every struct in
# proto/resolver/*.lcm, `resolver-spy --help` starts the JVM (no -Xincgc
# failure), and the spy starts and finds the resolver types: under Xvfb when
# xvfb-run is installed, else with java.awt.headless (which stops at the
# window, after type discovery). Exit 77 = skipped (no Java).
set -uo pipefail

launcher="" types_jar="" lcm_dir="" java_available=0
while (($# > 0)); do
  case $1 in
    --launcher) launcher=$2; shift ;;
    --types-jar) types_jar=$2; shift ;;
    --lcm-dir) lcm_dir=$2; shift ;;
    --java-available) java_available=$2; shift ;;
    *) echo "test_resolver_spy.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done

fail() {
  echo "FAIL: $*" >&2
  exit 1
}
skip() {
  echo "SKIP: $*"
  exit 77
}

[[ $java_available == 1 ]] || skip "javac, jar or lcm.jar not found at configure time; resolver-types.jar not built"
command -v java >/dev/null || [[ -x ${JAVA_HOME:-/nonexistent}/bin/java ]] || skip "no java runtime"
[[ -x $launcher ]] || fail "launcher $launcher missing or not executable"
[[ -f $types_jar ]] || fail "$types_jar missing (Java was found at configure time; build target resolver_spy_types)"

# --- 1. jar contents: one class per struct -----------------------------------
listing=$(unzip -Z1 "$types_jar" 2>/dev/null || jar tf "$types_jar") || fail "cannot list $types_jar"
expected=0
while read -r pkg name; do
  expected=$((expected + 1))
  grep -qx "$pkg/$name.class" <<<"$listing" || fail "$types_jar lacks $pkg/$name.class"
  echo "ok: $pkg/$name.class"
done < <(awk '/^[[:space:]]*package[[:space:]]/ { gsub(/[;[:space:]]/, "", $2); pkg = $2 }
              /^[[:space:]]*struct[[:space:]]/ { print pkg, $2 }' "$lcm_dir"/*.lcm)
((expected >= 5)) || fail "found only $expected structs in $lcm_dir"
for must in resolver/angle_t.class resolver/dq_t.class resolver/estimate_t.class resolver/health_t.class; do
  grep -qx "$must" <<<"$listing" || fail "$types_jar lacks $must"
done

# --- 2. --help: the JVM starts with our options ------------------------------
help_out=$(RESOLVER_SPY_TYPES_JAR=$types_jar "$launcher" --help 2>&1)
help_rc=$?
printf '%s\n' "$help_out" | sed 's/^/  help| /'
grep -q -- "-Xincgc" <<<"$help_out" && grep -qi "unrecognized" <<<"$help_out" && fail "JVM rejected -Xincgc"
grep -qi "Could not create the Java Virtual Machine" <<<"$help_out" && fail "JVM did not start"
((help_rc == 0)) || fail "resolver-spy --help exited $help_rc"
grep -q "usage: lcm-spy" <<<"$help_out" || fail "lcm.spy.Spy usage not printed"
echo "ok: --help (JVM started, lcm.spy.Spy usage printed)"

# --- 3. the spy starts and discovers the resolver types ----------------------
# A URL on the loopback memq provider needs no network (the container may have
# no multicast route); LCM_DEFAULT_URL must be honoured, so pass it that way.
url='memq://'
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if command -v xvfb-run >/dev/null && command -v Xvfb >/dev/null; then
  mode="Xvfb"
  # Wait for the type discovery, then check the window is still up 2 s later.
  # timeout leads its own process group, so TERM to it also ends Xvfb and java.
  LCM_DEFAULT_URL=$url RESOLVER_SPY_TYPES_JAR=$types_jar \
    timeout 60 xvfb-run -a "$launcher" >"$log" 2>&1 &
  pid=$!
  for _ in $(seq 1 200); do
    grep -q "LCM types" "$log" && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  sleep 2
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid"
    wait "$pid"
  else
    wait "$pid"
    rc=$?
    cat "$log"
    fail "spy under Xvfb exited ($rc) by itself; expected it to keep running"
  fi
else
  mode="java.awt.headless"
  # Headless AWT stops at the window (HeadlessException), after type discovery.
  LCM_DEFAULT_URL=$url RESOLVER_SPY_TYPES_JAR=$types_jar RESOLVER_SPY_JAVA_OPTS=-Djava.awt.headless=true \
    timeout 30 "$launcher" >"$log" 2>&1
fi
sed 's/^/  spy| /' "$log"
grep -q -- "--lcm-url=$url" "$log" || fail "LCM_DEFAULT_URL not passed on"
grep -qi "Unrecognized VM option" "$log" && fail "JVM rejected an option"
found=$(sed -n 's/.*Found \([0-9][0-9]*\) LCM types.*/\1/p' "$log" | head -n1)
[[ -n $found ]] || fail "spy did not report its LCM types ($mode)"
((found >= expected)) || fail "spy found $found LCM types, expected at least $expected ($mode)"
echo "ok: spy started ($mode), found $found LCM types"
