// Reads a SocketCAN interface until SIGINT/SIGTERM. Interface problems never
// end the daemon: a downed link (ENETDOWN) keeps the socket and goes on
// reading; a vanished interface (ENODEV) closes it and re-opens with backoff.
// Every such event is counted in health_t and printed once per episode.
// Once the frame that completes the samples is known ([can] wake_ids, learnt
// by default) the interface is read through two sockets, so that only that
// frame wakes the daemon (split_wake_source.h, wake_planner.h).
#pragma once

#include <functional>
#include <ostream>
#include <cstdint>
#include <string>
#include <vector>

#include "daemon/app/pipeline.h"
#include "daemon/app/stop_flag.h"

namespace resolver {

class SdNotifier;

struct LiveOptions {
  std::string iface;
  /// systemd notifications (READY, WATCHDOG, STATUS, STOPPING); null = none.
  SdNotifier* notifier = nullptr;
  int receive_buffer_bytes = 0;  ///< SO_RCVBUF; 0 = kernel default
  /// [can] wake_ids: learn the frame that completes samples and wake only
  /// for it (wake_auto, wake_planner.h), or these IDs (above 0x7FF: 29-bit;
  /// empty = every frame). Fixed at start (a SIGHUP does not change it).
  bool wake_auto = false;
  std::vector<std::uint32_t> wake_ids;
};

/// `current` returns the pipeline to feed (it may be rebuilt on SIGHUP by
/// `on_reload`, called from the loop when flags.reload is set).
void run_live(const LiveOptions& options, const std::function<Pipeline&()>& current,
              const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err);

}  // namespace resolver
