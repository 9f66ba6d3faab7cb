# replay: resolverd --can vcan0 records LCM to a file while canplayer replays the
# simulated demo log in real time; SIGTERM at the end.
. "$(dirname "$0")/lib.sh"
start_resolverd "$OUT/out.lcmlog" || exit 1
start_candump
play "$IN/demo.log"; fact canplayer_rc $?
fact frames_sent "$(wc -l < "$IN/demo.log")"
sleep 1
stop_candump
stop_resolverd
