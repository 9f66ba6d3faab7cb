# recreate: vcan0 is deleted (ENODEV) and created again between two halves of the
# log; resolverd must re-open it by itself and see every frame of both halves.
. "$(dirname "$0")/lib.sh"
start_resolverd "$OUT/out.lcmlog" || exit 1
play "$IN/half1.log"; fact canplayer1_rc $?
sleep 0.5
"$IP" link del dev "$IFACE"; fact link_del_rc $?
sleep 1.5
"$IP" link add dev "$IFACE" type vcan && "$IP" link set "$IFACE" up; fact link_add_rc $?
wait_for "$OUT/resolverd.stderr" "reading $IFACE" 2 20; fact reopened_rc $?
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$IN/half2.log") ))"
sleep 1
stop_resolverd
