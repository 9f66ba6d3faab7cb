#include "daemon/app/stop_flag.h"

#include <csignal>

namespace resolver {

namespace {
StopFlags* g_flags = nullptr;  // the one place a signal handler can reach; set once before handlers exist

extern "C" void on_signal(int sig) {
  if (g_flags == nullptr) return;
  if (sig == SIGHUP) {
    g_flags->reload.store(true);
  } else {
    g_flags->stop.store(true);
  }
}
}  // namespace

void install_signal_handlers(StopFlags& flags) {
  g_flags = &flags;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking read returns EINTR so the loop sees the flag
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGHUP, &sa, nullptr);
}

}  // namespace resolver
