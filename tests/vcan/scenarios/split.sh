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
start_error_dump
play "$IN/half1.log"; fact canplayer1_rc $?
send_error_frames
flap_link
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
stop_error_dump
stop_candump
stop_resolverd
