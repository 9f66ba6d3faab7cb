# linkflap: the interface goes down and comes back between two halves of the
# log; resolverd must keep its socket (ENETDOWN is counted, not fatal) and see
# every frame of both halves.
. "$(dirname "$0")/lib.sh"
start_resolverd "$OUT/out.lcmlog" || exit 1
play "$IN/half1.log"; fact canplayer1_rc $?
flap_link
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
stop_resolverd
