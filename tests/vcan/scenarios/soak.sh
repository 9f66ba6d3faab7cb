# soak: resolverd --can vcan0 at full bus rate (live_latency_sender: 8000
# default-bench frames/s plus one CAN error frame every 10 s) while the link
# flaps (down for 1 s every ~30 s). resolverd publishes on LCM multicast as it
# does on a bench; lcm-logger records only health_t and estimate_t (the full
# stream would not fit the guest's memory). The sender wakes once per resolver_vcan_burst frames
# (8: every 1 ms, as canplayer and USB adapters deliver; an emulated guest cannot
# wake 8000 times a second and keep up). Every 10 s resolverd's VmRSS goes to rss.txt.
# The host then checks that nothing was lost uncounted:
#   frames attempted = frames_seen + kernel_drops + frames refused while down
# and that the RSS stayed flat. Parameters (environment natively, kernel
# command line in the guest): resolver_vcan_soak_s (30: the suite's short
# variant; 600 for the full soak), resolver_vcan_soak_flap_s (30),
# resolver_vcan_wake_ids (none = resolverd's default, "auto"; e.g. 0x102 fixes [can] wake_ids).
. "$(dirname "$0")/lib.sh"
param() {
  eval "_v=\${$1:-}"
  [ -n "$_v" ] || _v=$(tr ' ' '\n' < /proc/cmdline 2>/dev/null | sed -n "s/^$1=//p")
  echo "${_v:-$2}"
}
secs=$(param resolver_vcan_soak_s 30)
flap=$(param resolver_vcan_soak_flap_s 30)
burst=$(param resolver_vcan_burst 8)
wake=$(param resolver_vcan_wake_ids none)
fact wake_ids "$wake"
if [ "$wake" = none ]; then printf '' > "$OUT/resolverd.toml"; else printf '[can]\nwake_ids = [%s]\n' "$wake" > "$OUT/resolverd.toml"; fi
# A short soak still flaps: at least twice per run, at least 4 s apart.
[ "$secs" -ge $((2 * flap)) ] || flap=$((secs / 3))
[ "$flap" -ge 4 ] || flap=4
fact soak_seconds "$secs"
fact flap_every_s "$flap"
fact burst "$burst"
url='udpm://239.255.76.67:7667?ttl=0'
rm -f "$OUT/out.lcmlog"
lcm-logger -q -f --lcm-url="$url" -c 'RESOLVER_HEALTH|RESOLVER_ESTIMATE' "$OUT/out.lcmlog" > "$OUT/lcm-logger.txt" 2>&1 & LOGGER_PID=$!
resolverd --can "$IFACE" --lcm "$url" --report "$OUT/report.json" --config "$OUT/resolverd.toml" \
  < /dev/null > "$OUT/resolverd.stdout" 2> "$OUT/resolverd.stderr" &
RESOLVERD_PID=$!
wait_for "$OUT/resolverd.stderr" "reading $IFACE" 1 20 || exit 1
rss() { sed -n 's/^VmRSS:[[:space:]]*\([0-9]*\) kB/\1/p' "/proc/$RESOLVERD_PID/status"; }
# Frames the kernel drops before any socket sees them (netif_rx backlog full,
# or queued as the link went down) show only here, not in SO_RXQ_OVFL.
stat() { cat "/sys/class/net/$IFACE/statistics/$1"; }
softnet_dropped() {  # column 2 of every CPU's row, hex
  _n=0; while read -r _a _b _rest; do _n=$((_n + 0x$_b)); done < /proc/net/softnet_stat; echo "$_n"
}
rx_dropped0=$(stat rx_dropped); softnet0=$(softnet_dropped)
echo "0 $(rss)" > "$OUT/rss.txt"
live_latency_sender --iface "$IFACE" --rate 8000 --burst "$burst" --seconds "$secs" --error-every 10 > "$OUT/sender.txt" 2>&1 &
SENDER_PID=$!
t0=$(now_s)
flaps=0; down_rc=0; up_rc=0; next_rss=10; next_flap=$flap
while kill -0 "$SENDER_PID" 2>/dev/null; do
  sleep 1
  el=$(awk -v a="$(now_s)" -v b="$t0" 'BEGIN { printf "%d", a - b }')
  if [ "$el" -ge "$next_rss" ]; then echo "$el $(rss)" >> "$OUT/rss.txt"; next_rss=$((next_rss + 10)); fi
  # One CPU snapshot a little into the run: who uses the (emulated) CPU.
  if [ "$el" -ge 5 ] && [ -z "${topped:-}" ]; then topped=1; top -b -n 1 | head -12; fi
  # No flap in the last 3 s: the link must be up for the sender's end marker.
  if [ "$el" -ge "$next_flap" ] && [ "$el" -le $((secs - 3)) ]; then
    "$IP" link set "$IFACE" down || down_rc=$?
    sleep 1
    "$IP" link set "$IFACE" up || up_rc=$?
    flaps=$((flaps + 1)); next_flap=$((next_flap + flap))
    echo "flap $flaps at ${el} s"
  fi
done
wait "$SENDER_PID"; fact sender_rc $?
fact iface_rx_dropped $(( $(stat rx_dropped) - rx_dropped0 ))
fact softnet_dropped $(( $(softnet_dropped) - softnet0 ))
echo "end $(rss)" >> "$OUT/rss.txt"
fact flaps "$flaps"; fact link_down_rc "$down_rc"; fact link_up_rc "$up_rc"
sed -n 's/^\(sender_[a-z_]*=.*\)$/\1/p' "$OUT/sender.txt" >> "$OUT/facts"
cat "$OUT/sender.txt"
sleep 1
stop_resolverd
sleep 1
kill "$LOGGER_PID"; wait "$LOGGER_PID" 2>/dev/null
echo "--- rss [s kB]"; cat "$OUT/rss.txt"
