#include "daemon/app/live_runner.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include "daemon/app/wake_planner.h"
#include "daemon/service/sd_notify.h"
#include "drivers/socketcan/link_monitor.h"
#include "drivers/socketcan/split_wake_source.h"

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
  so.receive_buffer_bytes = options.receive_buffer_bytes;
  WakePlanner planner(options.wake_auto, options.wake_ids);
  std::optional<SplitWakeSource> source;
  std::uint64_t drops_before = 0;  // kernel drops counted by sources already closed
  const Pipeline* wired = nullptr; // the pipeline that was told the wake IDs
  std::uint64_t silences_seen = 0; // SplitWakeSource::waking_silences() acted on
  // SO_MEMINFO once per this many reads (~1 s at a saturated bus) and at every timeout.
  constexpr int kReadsPerDropRefresh = 8192;
  int reads_since_refresh = 0;
  auto backoff = std::chrono::milliseconds(250);
  constexpr auto kMaxBackoff = std::chrono::milliseconds(5000);
  bool reported_down = false;
  // Link outages are counted from link events where rtnetlink is available:
  // a socket whose queue is never empty reports ENETDOWN late, and two flaps
  // in that time as one (drivers/socketcan/link_monitor.h).
  std::optional<LinkMonitor> link = LinkMonitor::open(options.iface);
  auto poll_link = [&](Pipeline& p) {
    if (!link) return;
    for (int n = link->poll_downs(); n > 0; --n) {
      p.count_problem("network_down", options.iface + " went down (link event); waiting for it to come back up");
    }
  };
  // ENETDOWN from the socket: counted only without link events, once per outage.
  auto note_network_down = [&](Pipeline& p) {
    poll_link(p);
    if (!link && !reported_down) {
      p.count_problem("network_down", options.iface + " is down (ENETDOWN); waiting for it to come back up");
    }
    reported_down = true;
  };
  std::uint64_t drops_reported = 0;
  CanFrame frame;
  SdNotifier* notify = options.notifier;
  NotifyPacer pacer(notify != nullptr ? notify->watchdog_interval() : std::chrono::microseconds(0),
                    std::chrono::seconds(1));
  bool announced_ready = false;
  std::int64_t frames_at_status = 0;
  auto status_time = Clock::now();
  std::string waiting_for;  // non-empty while the interface cannot be opened

  // systemd: watchdog pings and a one-line STATUS= every second.
  auto service_tick = [&](Pipeline& p) {
    if (notify == nullptr) return;
    const auto now = Clock::now();
    const NotifyPacer::Due due = pacer.poll(now);
    if (due.watchdog) notify->watchdog();
    if (!due.status) return;
    const std::int64_t seen = p.intake().stats().frames_seen;
    const double dt = std::chrono::duration<double>(now - status_time).count();
    const double rate = dt > 0.0 ? static_cast<double>(seen - frames_at_status) / dt : 0.0;
    frames_at_status = seen;
    status_time = now;
    std::string detail;
    for (const auto& [reason, n] : p.intake().rejects().all()) {
      detail += (detail.empty() ? "" : " ") + reason + "=" + std::to_string(n);
    }
    const auto& est = p.processor().estimator();
    const std::string extra = !waiting_for.empty() ? waiting_for
                              : est.converged()    ? "alpha " + std::to_string(est.alpha())
                                                   : "estimating";
    notify->status(format_service_status(options.iface, rate, p.intake().rejects().total(), detail, extra));
  };

  // Changes which frames wake the reader (WakePlanner), on the live sockets:
  // nothing queued is lost, a frame both sockets got in the switch is handed
  // out once (SplitWakeSource::set_wake).
  auto switch_wake = [&](Pipeline& pipeline, std::vector<std::uint32_t> ids) {
    const std::string before = WakePlanner::describe(planner.wake_ids());
    try {
      source->set_wake(exact_id_filters(ids));
    } catch (const SocketCanError& e) {
      pipeline.count_problem("wake_switch_failed", std::string(e.what()) + "; still woken by " + before);
      planner.switched(planner.wake_ids());  // count again rather than retry at once
      return;
    }
    err << "resolverd: " << options.iface << ": "
        << (ids.empty() ? before + " no longer completes the samples; every frame wakes the reader again"
                        : "samples are completed by " + WakePlanner::describe(ids) +
                              "; only it wakes the reader now, the other frames wait in a second socket")
        << "\n";
    planner.switched(ids);
    pipeline.set_wake_ids(std::move(ids));
  };

  while (!flags.stop.load()) {
    if (flags.reload.exchange(false)) on_reload();
    Pipeline& pipeline = current();
    service_tick(pipeline);
    if (!source) {
      try {
        source.emplace(SplitWakeSource::open(so, exact_id_filters(planner.wake_ids())));
        err << "resolverd: reading " << options.iface;
        if (!planner.wake_ids().empty()) {
          err << " (two sockets: woken only by " << WakePlanner::describe(planner.wake_ids()) << ")";
        }
        err << "\n";
        backoff = std::chrono::milliseconds(250);
        reported_down = false;
        waiting_for.clear();
        if (notify != nullptr && !announced_ready) {
          notify->ready();  // the socket is bound and LCM is up
          announced_ready = true;
        }
      } catch (const SocketCanError& e) {
        waiting_for = "waiting for " + options.iface;
        pipeline.count_problem("interface_unavailable", std::string(e.what()) + "; retrying in " +
                                                           std::to_string(backoff.count()) + " ms");
        pipeline.tick(wall_us());
        // Sleep in slices so watchdog pings and SIGTERM are not held up by the backoff.
        const auto until = Clock::now() + backoff;
        while (Clock::now() < until && !flags.stop.load()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          service_tick(pipeline);
        }
        backoff = std::min(backoff * 2, kMaxBackoff);
        continue;
      }
    }
    if (wired != &pipeline) {  // first pass, or a SIGHUP rebuilt it
      pipeline.set_wake_ids(planner.wake_ids());
      wired = &pipeline;
    }
    const ReadStatus status = source->read(frame);
    switch (status) {
      case ReadStatus::kFrame: {
        reported_down = false;
        const std::int64_t completed = pipeline.completing_frames().total();
        pipeline.feed(frame, 0, Clock::now());
        if (!planner.auto_mode()) break;
        if (pipeline.completing_frames().total() != completed) {
          if (auto ids = planner.on_sample_completed_by(frame.id)) switch_wake(pipeline, std::move(*ids));
        }
        if (source->waking_silences() != silences_seen) {
          silences_seen = source->waking_silences();
          if (auto ids = planner.on_waking_silence()) switch_wake(pipeline, std::move(*ids));
        }
        break;
      }
      case ReadStatus::kTimeout:
      case ReadStatus::kInterrupted:
        break;
      case ReadStatus::kTruncated:
        pipeline.count_problem("truncated_read", options.iface + ": short read from the CAN socket, frame dropped");
        break;
      case ReadStatus::kNetworkDown:
        // The socket stays bound; frames resume when the link comes back up
        // (no pause when link events say it already has: the queue is behind).
        note_network_down(pipeline);
        if (!link || link->down()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        break;
      case ReadStatus::kDeviceGone:
        pipeline.count_problem("device_gone", options.iface + " disappeared (ENODEV); re-opening with backoff");
        source->refresh_kernel_drops();  // drops after the last frame it queued, before the socket closes
        drops_before += source->stats().kernel_drops;
        source.reset();
        silences_seen = 0;
        pipeline.restart_sequence();
        break;
    }
    if (source) {
      if (status == ReadStatus::kTimeout || ++reads_since_refresh >= kReadsPerDropRefresh) {
        // Drops after the last frame a socket queued show only this way.
        source->refresh_kernel_drops();
        poll_link(pipeline);
        reads_since_refresh = 0;
      }
      const std::uint64_t drops = drops_before + source->stats().kernel_drops;
      pipeline.set_kernel_drops(static_cast<std::int64_t>(drops));
      if (drops > drops_reported) {
        pipeline.count_problem("kernel_drop", options.iface + ": kernel dropped " + std::to_string(drops - drops_reported) +
                                                  " frame(s) (socket receive queue overflow)");
        drops_reported = drops;
      }
    }
    pipeline.tick(wall_us());
  }
  if (notify != nullptr) notify->stopping();
  // Frames already queued in the socket when SIGTERM came are still data:
  // drain them (bounded) so nothing received is dropped uncounted.
  if (source) {
    source->set_read_timeout(std::chrono::milliseconds(0));
    Pipeline& pipeline = current();
    // Only an empty queue ends it: a link that went down while the reader was
    // behind reports that ahead of the frames still queued after it.
    for (int i = 0; i < 1'000'000; ++i) {
      const ReadStatus status = source->read(frame);
      if (status == ReadStatus::kFrame) {
        pipeline.feed(frame, 0, Clock::now());
        reported_down = false;
      } else if (status == ReadStatus::kNetworkDown) {
        note_network_down(pipeline);
      } else if (status == ReadStatus::kTruncated) {
        pipeline.count_problem("truncated_read", options.iface + ": short read from the CAN socket, frame dropped");
      } else if (status != ReadStatus::kInterrupted) {
        break;  // kTimeout: empty; kDeviceGone: nothing more to read
      }
    }
    source->refresh_kernel_drops();
    pipeline.set_kernel_drops(static_cast<std::int64_t>(drops_before + source->stats().kernel_drops));
  }
  poll_link(current());
  current().finish();
}

}  // namespace resolver
