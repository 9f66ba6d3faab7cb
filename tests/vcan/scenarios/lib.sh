# Helpers shared by the vcan scenarios (POSIX sh: busybox ash in the guest, dash
# or bash on a bench PC). A scenario is run with:
#   IN     folder with the inputs the host prepared (demo.log, half1.log, half2.log)
#   OUT    folder for everything it produces (the host checks it afterwards)
#   IFACE  classic vcan interface (vcan0); FD_IFACE an FD one (vcan1, MTU 72)
#   IP     iproute2's ip (the guest names /usr/sbin/ip: busybox sh prefers its applets)
# and writes key=value facts to $OUT/facts for the host-side checks.
set -u
: "${IN:?}" "${OUT:?}" "${IFACE:=vcan0}" "${FD_IFACE:=vcan1}" "${IP:=ip}"
RESOLVERD_PID=""

fact() { echo "$1=$2" >> "$OUT/facts"; echo "fact $1=$2"; }
now_s() { cut -d' ' -f1 /proc/uptime; }

# wait_for FILE TEXT COUNT SECONDS: until TEXT occurs COUNT times in FILE.
wait_for() {
  _n=0
  while [ "$_n" -lt $(( $4 * 10 )) ]; do
    if [ "$(grep -c -- "$2" "$1" 2>/dev/null || true)" -ge "$3" ]; then return 0; fi
    sleep 0.1; _n=$((_n + 1))
  done
  echo "timeout: '$2' x$3 not in $1 after $4 s"; return 1
}

# start_resolverd LCMLOG [more resolverd args]: as systemd would, stdin from
# /dev/null, output to files, in the background; returns once it reads $IFACE.
start_resolverd() {
  _log="$1"; shift
  rm -f "$_log"
  resolverd --can "$IFACE" --lcm "file://$_log?mode=w" "$@" \
    < /dev/null > "$OUT/resolverd.stdout" 2> "$OUT/resolverd.stderr" &
  RESOLVERD_PID=$!
  wait_for "$OUT/resolverd.stderr" "reading $IFACE" 1 20
}

# stop_resolverd: SIGTERM (systemd's stop), wait, record the exit code.
stop_resolverd() {
  kill -TERM "$RESOLVERD_PID"
  wait "$RESOLVERD_PID"; _rc=$?
  fact resolverd_rc "$_rc"
  echo "--- resolverd stderr"; cat "$OUT/resolverd.stderr"
  echo "--- resolverd stdout (report)"; cat "$OUT/resolverd.stdout"
  return 0
}

# play LOG: canplayer in the log's own timing, candump's interface can0 -> $IFACE.
# canplayer sleeps CANPLAYER_GAP_MS (its -g, default 1 ms) between looks at the
# clock and then sends every frame that has fallen due: frames leave in bursts
# at that granularity. 0 = busy loop, the log's timing as closely as the CPU allows.
play() {
  _t0=$(now_s)
  canplayer -g "${CANPLAYER_GAP_MS:-1}" -I "$1" "$IFACE=can0"; _rc=$?
  echo "canplayer $1: rc=$_rc, $(wc -l < "$1") frames, $_t0 .. $(now_s) s uptime"
  return $_rc
}

# An independent listener: candump counts what really went over the bus.
start_candump() { candump -L "$IFACE" > "$OUT/candump.log" 2> "$OUT/candump.err" & CANDUMP_PID=$!; sleep 0.3; }
stop_candump() { sleep 0.3; kill "$CANDUMP_PID" 2>/dev/null; wait "$CANDUMP_PID" 2>/dev/null; fact frames_on_bus "$(wc -l < "$OUT/candump.log")"; }

# flap_link: $IFACE down for 1 s and up again, 0.5 s of quiet on each side.
flap_link() {
  sleep 0.5
  "$IP" link set "$IFACE" down; fact link_down_rc $?
  sleep 1
  "$IP" link set "$IFACE" up; fact link_up_rc $?
  sleep 0.5
}

# Error frames: cansend with CAN_ERR_FLAG (0x20000000) in the ID, witnessed by
# a candump with an error mask (resolverd must count exactly what it saw).
start_error_dump() { candump -L "$IFACE,0~0,#FFFFFFFF" > "$OUT/candump_err.log" 2>&1 & ERRDUMP_PID=$!; sleep 0.3; }
send_error_frames() {
  _n=0
  for _id in 20000004 20000010 20000040; do  # controller problem, bus warning... (linux/can/error.h)
    cansend "$IFACE" "$_id#0000000000000000"; fact "cansend_${_id}_rc" $?; _n=$((_n + 1))
  done
  fact error_frames_sent "$_n"
}
stop_error_dump() {
  kill "$ERRDUMP_PID"; wait "$ERRDUMP_PID" 2>/dev/null
  fact error_frames_seen_by_candump "$(grep -c ' 2000' "$OUT/candump_err.log" || true)"
}
