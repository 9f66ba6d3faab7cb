# latency: live_latency_bench on a real CAN_RAW socket (vcan0): its paced
# sender writes default-bench frames at 8000 frames/s, its reader runs
# resolverd's live read path (SocketCanSource::open, Pipeline, LcmOutput) and
# times each frame from the kernel's receive stamp to the LCM publish return.
# In the QEMU guest this is emulated (TCG, one vCPU shared by sender and
# reader): the table shows how the path behaves, not a bench PC's speed.
# Parameters (environment natively, kernel command line in the guest):
#   resolver_vcan_latency_s    seconds per run (5)
#   resolver_vcan_latency_runs runs (1)
#   resolver_vcan_latency_lcm  LCM URL of the output (memq://)
#   resolver_vcan_burst        frames per sender wake-up (8 = one burst per ms;
#                              1 = evenly spaced, more than the emulated guest keeps up with)
#   resolver_vcan_wake_ids     resolverd's [can] wake_ids, comma-separated (none)
# The sender runs SCHED_OTHER here: on the guest's single vCPU a real-time
# sender that falls behind would starve the reader it is measuring.
. "$(dirname "$0")/lib.sh"
# param NAME DEFAULT: $NAME from the environment, else NAME=... on /proc/cmdline.
param() {
  eval "_v=\${$1:-}"
  [ -n "$_v" ] || _v=$(tr ' ' '\n' < /proc/cmdline 2>/dev/null | sed -n "s/^$1=//p")
  echo "${_v:-$2}"
}
secs=$(param resolver_vcan_latency_s 5)
runs=$(param resolver_vcan_latency_runs 1)
lcm=$(param resolver_vcan_latency_lcm memq://)
burst=$(param resolver_vcan_burst 8)
wake=$(param resolver_vcan_wake_ids none)
fact latency_seconds "$secs"
fact latency_burst "$burst"
fact wake_ids "$wake"
set --
[ "$wake" = none ] || set -- --wake-ids $(echo "$wake" | tr ',' ' ')
live_latency_bench --iface "$IFACE" --seconds "$secs" --runs "$runs" --lcm "$lcm" --burst "$burst" --sender-fifo 0 \
  --json "$OUT/latency.json" "$@" > "$OUT/latency.txt" 2>&1
fact latency_rc $?
cat "$OUT/latency.txt"
