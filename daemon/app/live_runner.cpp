#include "daemon/app/live_runner.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include "drivers/socketcan/socketcan_source.h"

namespace resolver {

namespace {
using Clock = std::chrono::steady_clock;

std::int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}
}  // namespace

void run_live(const LiveOptions& options, const std::function<Pipeline&()>& current,
              const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err) {
  SocketCanOptions so;
  so.iface = options.iface;
  std::optional<SocketCanSource> source;
  auto backoff = std::chrono::milliseconds(250);
  constexpr auto kMaxBackoff = std::chrono::milliseconds(5000);
  bool reported_down = false;
  std::uint64_t drops_reported = 0;
  CanFrame frame;

  while (!flags.stop.load()) {
    if (flags.reload.exchange(false)) on_reload();
    Pipeline& pipeline = current();
    if (!source) {
      try {
        source.emplace(SocketCanSource::open(so));
        err << "resolverd: reading " << options.iface << "\n";
        backoff = std::chrono::milliseconds(250);
        reported_down = false;
      } catch (const SocketCanError& e) {
        pipeline.count_problem("interface_unavailable", std::string(e.what()) + "; retrying in " +
                                                           std::to_string(backoff.count()) + " ms");
        pipeline.tick(wall_us());
        std::this_thread::sleep_for(backoff);
        backoff = std::min(backoff * 2, kMaxBackoff);
        continue;
      }
    }
    const ReadStatus status = source->read(frame);
    switch (status) {
      case ReadStatus::kFrame:
        reported_down = false;
        pipeline.feed(frame, 0, Clock::now());
        break;
      case ReadStatus::kTimeout:
      case ReadStatus::kInterrupted:
        break;
      case ReadStatus::kTruncated:
        pipeline.count_problem("truncated_read", options.iface + ": short read from the CAN socket, frame dropped");
        break;
      case ReadStatus::kNetworkDown:
        // The socket stays bound; frames resume when the link comes back up.
        if (!reported_down) {
          pipeline.count_problem("network_down", options.iface + " is down (ENETDOWN); waiting for it to come back up");
          reported_down = true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        break;
      case ReadStatus::kDeviceGone:
        pipeline.count_problem("device_gone", options.iface + " disappeared (ENODEV); re-opening with backoff");
        source.reset();
        pipeline.restart_sequence();
        break;
    }
    if (source) {
      const std::uint64_t drops = source->stats().kernel_drops;
      pipeline.set_kernel_drops(static_cast<std::int64_t>(drops));
      if (drops > drops_reported) {
        pipeline.count_problem("kernel_drop", options.iface + ": kernel dropped " + std::to_string(drops - drops_reported) +
                                                  " frame(s) (socket receive queue overflow)");
        drops_reported = drops;
      }
    }
    pipeline.tick(wall_us());
  }
  current().finish();
}

}  // namespace resolver
