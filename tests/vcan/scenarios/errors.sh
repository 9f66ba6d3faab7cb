# errors: can an error frame reach resolverd over vcan? cansend with CAN_ERR_FLAG
# (0x20000000) in the ID, between two halves of the demo log. vcan echoes what a
# raw socket writes; whether the kernel delivers an error-flagged frame written
# by user space to an error-filter reader is what this scenario finds out.
. "$(dirname "$0")/lib.sh"
start_resolverd "$OUT/out.lcmlog" || exit 1
start_candump
candump -L "$IFACE,0~0,#FFFFFFFF" > "$OUT/candump_err.log" 2>&1 & ERRDUMP_PID=$!
sleep 0.3
play "$IN/half1.log"; fact canplayer1_rc $?
n=0
for id in 20000004 20000010 20000040; do      # controller problem, bus warning... (linux/can/error.h)
  cansend "$IFACE" "$id#0000000000000000"; fact "cansend_${id}_rc" $?; n=$((n + 1))
done
fact error_frames_sent "$n"
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
kill "$ERRDUMP_PID"; wait "$ERRDUMP_PID" 2>/dev/null
fact error_frames_seen_by_candump "$(grep -c ' 2000' "$OUT/candump_err.log" || true)"
stop_candump
stop_resolverd
