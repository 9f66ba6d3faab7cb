# sighup: SIGHUP with a valid config reloads it; SIGHUP with a broken config keeps
# the running one; the daemon keeps reading throughout.
. "$(dirname "$0")/lib.sh"
printf '[output]\nripple_revolutions = 16\n' > "$OUT/resolverd.toml"
start_resolverd "$OUT/out.lcmlog" --config "$OUT/resolverd.toml" || exit 1
play "$IN/half1.log"; fact canplayer1_rc $?
sleep 0.5
kill -HUP "$RESOLVERD_PID"
wait_for "$OUT/resolverd.stderr" "config reloaded" 1 10; fact reload_ok_rc $?
printf '[output]\nripple_revolutions = "many"\n' > "$OUT/resolverd.toml"
kill -HUP "$RESOLVERD_PID"
wait_for "$OUT/resolverd.stderr" "reload failed" 1 10; fact reload_bad_rc $?
play "$IN/half2.log"; fact canplayer2_rc $?
fact frames_sent_half1 "$(wc -l < "$IN/half1.log")"
fact frames_sent_half2 "$(wc -l < "$IN/half2.log")"
sleep 1
stop_resolverd
