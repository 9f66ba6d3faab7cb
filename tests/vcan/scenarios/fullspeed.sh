# fullspeed: canplayer -t sends the demo log as fast as the CPU allows (tx queue
# raised so canplayer itself does not hit ENOBUFS). resolverd runs with a
# deliberately tiny socket receive buffer so the kernel must drop frames: every
# frame sent has to be either seen or counted in kernel_drops (SO_RXQ_OVFL).
. "$(dirname "$0")/lib.sh"
$IP link set "$IFACE" txqueuelen 10000; fact txqueuelen_rc $?
printf '[can]\nreceive_buffer_bytes = 4096\n' > "$OUT/tiny_rcvbuf.toml"
start_resolverd "$OUT/out.lcmlog" --config "$OUT/tiny_rcvbuf.toml" || exit 1
_t0=$(now_s)
canplayer -t -I "$IN/demo.log" "$IFACE=can0"; fact canplayer_rc $?
echo "canplayer -t: $(wc -l < "$IN/demo.log") frames, $_t0 .. $(now_s) s uptime"
sleep 0.5
# The kernel reports drops (SO_RXQ_OVFL) only with the next delivered frame: one
# marker frame (an ID outside the layout, counted as unknown_id) carries the final count.
cansend "$IFACE" 7FF#00; fact marker_rc $?
fact frames_sent "$(( $(wc -l < "$IN/demo.log") + 1 ))"
sleep 1
stop_resolverd
