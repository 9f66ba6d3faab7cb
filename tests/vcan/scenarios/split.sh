# split: resolverd with [can] wake_ids = [0x102] reads vcan0 through two
# sockets (kernel CAN_RAW filters: 0x102 and error frames on the waking one,
# every other ID on the quiet one, inverted and joined filters). Error frames
# and a link flap between the two halves of the log: every frame must still
# arrive once, in order (all samples complete), and none may wait for a wake-up
# (no completed_by_quiet_frame).
. "$(dirname "$0")/lib.sh"
printf '[can]\nwake_ids = [0x102]\n' > "$OUT/resolverd.toml"
start_resolverd "$OUT/out.lcmlog" --config "$OUT/resolverd.toml" || exit 1
start_candump
candump -L "$IFACE,0~0,#FFFFFFFF" > "$OUT/candump_err.log" 2>&1 & ERRDUMP_PID=$!
sleep 0.3
play "$IN/half1.log"; fact canplayer1_rc $?
n=0
for id in 20000004 20000010 20000040; do
  cansend "$IFACE" "$id#0000000000000000"; n=$((n + 1))
done
fact error_frames_sent "$n"
sleep 0.5
"$IP" link set "$IFACE" down; fact link_down_rc $?
sleep 1
"$IP" link set "$IFACE" up; fact link_up_rc $?
sleep 0.5
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
kill "$ERRDUMP_PID"; wait "$ERRDUMP_PID" 2>/dev/null
fact error_frames_seen_by_candump "$(grep -c ' 2000' "$OUT/candump_err.log" || true)"
stop_candump
stop_resolverd
