// Signals -> flags the main loop polls. Handlers only store to lock-free
// atomics (async-signal-safe); all work happens in the loop.
#pragma once

#include <atomic>

namespace resolver {

struct StopFlags {
  std::atomic<bool> stop{false};    ///< SIGINT / SIGTERM: finish and exit cleanly
  std::atomic<bool> reload{false};  ///< SIGHUP: reload the config
};

/// Installs SIGINT/SIGTERM/SIGHUP handlers that set `flags`. Call once.
void install_signal_handlers(StopFlags& flags);

}  // namespace resolver
