# wakechange: the default [can] wake_ids = "auto" while the bench changes. The
# first half of the log has the reference encoder (REFERENCE_ANGLE, 0x102,
# completes each sample): resolverd learns 0x102 and splits its socket. In the
# second half the encoder is unplugged (no 0x102 frames): no waking frame
# comes, so resolverd must go back to waking for every frame instead of
# handing the frames out a read timeout late. Every frame counted once.
. "$(dirname "$0")/lib.sh"
grep -v ' 102#' "$IN/half2.log" > "$OUT/half2_noref.log"
start_resolverd "$OUT/out.lcmlog" || exit 1
play "$IN/half1.log"; fact canplayer1_rc $?
play "$OUT/half2_noref.log"; fact canplayer2_rc $?
fact frames_sent "$(( $(wc -l < "$IN/half1.log") + $(wc -l < "$OUT/half2_noref.log") ))"
sleep 1
stop_resolverd
