# model: live model discovery (issue 4). model1.log/model2.log hide quadrature next
# to alpha. resolverd starts with the seed model (amplitude imbalance only), so its
# model_fit_t windows say missing_effect and rank quadrature first; SIGHUP loads the
# model with quadrature added and the windows of model2.log say explained; a
# SIGHUP with an unknown effect is refused and the running model kept.
. "$(dirname "$0")/lib.sh"
printf '[model]\neffects = ["amplitude_imbalance"]\nwindow_revolutions = 8\n' > "$OUT/resolverd.toml"
start_resolverd "$OUT/out.lcmlog" --config "$OUT/resolverd.toml" || exit 1
play "$IN/model1.log"; fact canplayer1_rc $?
sleep 1
printf '[model]\neffects = ["amplitude_imbalance", "quadrature"]\nwindow_revolutions = 8\n' > "$OUT/resolverd.toml"
kill -HUP "$RESOLVERD_PID"
wait_for "$OUT/resolverd.stderr" "config reloaded" 1 10; fact reload_ok_rc $?
play "$IN/model2.log"; fact canplayer2_rc $?
sleep 1
printf '[model]\neffects = ["flux_capacitor"]\n' > "$OUT/resolverd.toml"
kill -HUP "$RESOLVERD_PID"
wait_for "$OUT/resolverd.stderr" "reload failed" 1 10; fact reload_bad_rc $?
stop_resolverd
