# fd: resolverd on the FD-capable vcan1 (MTU 72): classic frames of the demo log
# plus CAN FD frames written with cansend; every frame must be seen, the FD ones
# must not break the decoding of the classic ones.
. "$(dirname "$0")/lib.sh"
IFACE="$FD_IFACE"
fact mtu "$(cat /sys/class/net/$IFACE/mtu)"
start_resolverd "$OUT/out.lcmlog" || exit 1
play "$IN/half1.log"; fact canplayer1_rc $?
n=0
for f in '123##1.0011223344556677.8899AABBCCDDEEFF' '100##0.00112233445566778899AABBCCDDEEFF00112233445566778899AABBCCDDEEFF'; do
  cansend "$IFACE" "$f"; fact "cansend_fd${n}_rc" $?; n=$((n + 1))
done
fact fd_frames_sent "$n"
fact frames_sent "$(wc -l < "$IN/half1.log")"
sleep 1
stop_resolverd
