# errors: can an error frame reach resolverd over vcan? cansend with CAN_ERR_FLAG
# (0x20000000) in the ID, between two halves of the demo log. vcan echoes what a
# raw socket writes; whether the kernel delivers an error-flagged frame written
# by user space to an error-filter reader is what this scenario finds out.
. "$(dirname "$0")/lib.sh"
start_resolverd "$OUT/out.lcmlog" || exit 1
start_candump
start_error_dump
play "$IN/half1.log"; fact canplayer1_rc $?
send_error_frames
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
stop_error_dump
stop_candump
stop_resolverd
