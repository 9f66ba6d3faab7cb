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

namespace {

/// One live run: the sockets, the wake plan, link events, kernel drops and the
/// systemd notifications; run() is the read loop, each method one of its steps.
class LiveReader {
 public:
  LiveReader(const LiveOptions& options, const std::function<Pipeline&()>& current, std::ostream& err)
      : options_(options),
        current_(current),
        err_(err),
        planner_(options.wake_auto, options.wake_ids),
        link_(LinkMonitor::open(options.iface)),
        notify_(options.notifier),
        pacer_(notify_ != nullptr ? notify_->watchdog_interval() : std::chrono::microseconds(0),
               std::chrono::seconds(1)) {
    so_.iface = options.iface;
    so_.receive_buffer_bytes = options.receive_buffer_bytes;
  }

  void run(const std::function<void()>& on_reload, StopFlags& flags) {
    while (!flags.stop.load()) {
      if (flags.reload.exchange(false)) on_reload();
      Pipeline& pipeline = current_();
      service_tick(pipeline);
      if (!source_ && !open_source(pipeline, flags)) continue;
      if (wired_ != &pipeline) {  // first pass, or a SIGHUP rebuilt it
        pipeline.set_wake_ids(planner_.wake_ids());
        wired_ = &pipeline;
      }
      CanFrame frame;
      const ReadStatus status = source_->read(frame);
      handle(pipeline, status, frame);
      if (source_) account_drops(pipeline, status == ReadStatus::kTimeout);
      pipeline.tick(wall_us());
    }
    if (notify_ != nullptr) notify_->stopping();
    drain();
    current_().finish();
  }

 private:
  /// Opens the interface (both sockets once the wake IDs are known). On failure
  /// counts it and waits the backoff in slices, so watchdog pings and SIGTERM are
  /// not held up; returns whether a source is open.
  bool open_source(Pipeline& pipeline, const StopFlags& flags) {
    try {
      source_.emplace(SplitWakeSource::open(so_, exact_id_filters(planner_.wake_ids())));
    } catch (const SocketCanError& e) {
      waiting_for_ = "waiting for " + options_.iface;
      pipeline.count_problem("interface_unavailable",
                             std::string(e.what()) + "; retrying in " + std::to_string(backoff_.count()) + " ms");
      pipeline.tick(wall_us());
      const auto until = Clock::now() + backoff_;
      while (Clock::now() < until && !flags.stop.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        service_tick(pipeline);
      }
      backoff_ = std::min(backoff_ * 2, kMaxBackoff);
      return false;
    }
    err_ << "resolverd: reading " << options_.iface;
    if (!planner_.wake_ids().empty()) {
      err_ << " (two sockets: woken only by " << WakePlanner::describe(planner_.wake_ids()) << ")";
    }
    err_ << "\n";
    backoff_ = std::chrono::milliseconds(250);
    reported_down_ = false;
    waiting_for_.clear();
    if (notify_ != nullptr && !announced_ready_) {
      notify_->ready();  // the socket is bound and LCM is up
      announced_ready_ = true;
    }
    return true;
  }

  /// One read's outcome: a frame fed (and the wake plan updated), or the
  /// interface event counted.
  void handle(Pipeline& pipeline, ReadStatus status, const CanFrame& frame) {
    switch (status) {
      case ReadStatus::kFrame:
        reported_down_ = false;
        feed(pipeline, frame);
        break;
      case ReadStatus::kTimeout:
      case ReadStatus::kInterrupted:
        break;
      case ReadStatus::kTruncated:
        pipeline.count_problem("truncated_read", options_.iface + ": short read from the CAN socket, frame dropped");
        break;
      case ReadStatus::kNetworkDown:
        // The socket stays bound; frames resume when the link comes back up
        // (no pause when link events say it already has: the queue is behind).
        note_network_down(pipeline);
        if (!link_ || link_->down()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        break;
      case ReadStatus::kDeviceGone:
        pipeline.count_problem("device_gone", options_.iface + " disappeared (ENODEV); re-opening with backoff");
        source_->refresh_kernel_drops();  // drops after the last frame it queued, before the socket closes
        drops_before_ += source_->stats().kernel_drops;
        source_.reset();
        silences_seen_ = 0;
        pipeline.restart_sequence();
        break;
    }
  }

  /// Feeds a frame; in auto mode learns which frame completes the samples, and
  /// goes back to every frame when the waking one falls silent.
  void feed(Pipeline& pipeline, const CanFrame& frame) {
    const std::int64_t completed = pipeline.completing_frames().total();
    pipeline.feed(frame, 0, Clock::now());
    if (!planner_.auto_mode()) return;
    if (pipeline.completing_frames().total() != completed) {
      if (auto ids = planner_.on_sample_completed_by(frame.id)) switch_wake(pipeline, std::move(*ids));
    }
    if (source_->waking_silences() != silences_seen_) {
      silences_seen_ = source_->waking_silences();
      if (auto ids = planner_.on_waking_silence()) switch_wake(pipeline, std::move(*ids));
    }
  }

  /// Changes which frames wake the reader (WakePlanner), on the live sockets:
  /// nothing queued is lost, a frame both sockets got in the switch is handed
  /// out once (SplitWakeSource::set_wake).
  void switch_wake(Pipeline& pipeline, std::vector<std::uint32_t> ids) {
    const std::string before = WakePlanner::describe(planner_.wake_ids());
    try {
      source_->set_wake(exact_id_filters(ids));
    } catch (const SocketCanError& e) {
      pipeline.count_problem("wake_switch_failed", std::string(e.what()) + "; still woken by " + before);
      planner_.switched(planner_.wake_ids());  // count again rather than retry at once
      return;
    }
    err_ << "resolverd: " << options_.iface << ": "
         << (ids.empty() ? before + " no longer completes the samples; every frame wakes the reader again"
                         : "samples are completed by " + WakePlanner::describe(ids) +
                               "; only it wakes the reader now, the other frames wait in a second socket")
         << "\n";
    planner_.switched(ids);
    pipeline.set_wake_ids(std::move(ids));
  }

  /// Link outages are counted from link events where rtnetlink is available: a
  /// socket whose queue is never empty reports ENETDOWN late, and two flaps in
  /// that time as one (drivers/socketcan/link_monitor.h).
  void poll_link(Pipeline& pipeline) {
    if (!link_) return;
    for (int n = link_->poll_downs(); n > 0; --n) {
      pipeline.count_problem("network_down", options_.iface + " went down (link event); waiting for it to come back up");
    }
  }

  /// ENETDOWN from the socket: counted only without link events, once per outage.
  void note_network_down(Pipeline& pipeline) {
    poll_link(pipeline);
    if (!link_ && !reported_down_) {
      pipeline.count_problem("network_down", options_.iface + " is down (ENETDOWN); waiting for it to come back up");
    }
    reported_down_ = true;
  }

  /// Kernel drops: SO_MEMINFO once per kReadsPerDropRefresh reads and at every
  /// timeout (drops after the last frame a socket queued show only this way),
  /// with the link events; new drops counted and printed.
  void account_drops(Pipeline& pipeline, bool timed_out) {
    if (timed_out || ++reads_since_refresh_ >= kReadsPerDropRefresh) {
      source_->refresh_kernel_drops();
      poll_link(pipeline);
      reads_since_refresh_ = 0;
    }
    const std::uint64_t drops = drops_before_ + source_->stats().kernel_drops;
    pipeline.set_kernel_drops(static_cast<std::int64_t>(drops));
    if (drops > drops_reported_) {
      pipeline.count_problem("kernel_drop", options_.iface + ": kernel dropped " + std::to_string(drops - drops_reported_) +
                                                " frame(s) (socket receive queue overflow)");
      drops_reported_ = drops;
    }
  }

  /// Frames already queued in the socket when SIGTERM came are still data: drain
  /// them (bounded) so nothing received is dropped uncounted. Only an empty queue
  /// ends it: a link that went down while the reader was behind reports that
  /// ahead of the frames still queued after it.
  void drain() {
    Pipeline& pipeline = current_();
    if (source_) {
      source_->set_read_timeout(std::chrono::milliseconds(0));
      CanFrame frame;
      for (int i = 0; i < 1'000'000; ++i) {
        const ReadStatus status = source_->read(frame);
        if (status == ReadStatus::kFrame) {
          pipeline.feed(frame, 0, Clock::now());
          reported_down_ = false;
        } else if (status == ReadStatus::kNetworkDown) {
          note_network_down(pipeline);
        } else if (status == ReadStatus::kTruncated) {
          pipeline.count_problem("truncated_read", options_.iface + ": short read from the CAN socket, frame dropped");
        } else if (status != ReadStatus::kInterrupted) {
          break;  // kTimeout: empty; kDeviceGone: nothing more to read
        }
      }
      source_->refresh_kernel_drops();
      pipeline.set_kernel_drops(static_cast<std::int64_t>(drops_before_ + source_->stats().kernel_drops));
    }
    poll_link(pipeline);
  }

  /// systemd: watchdog pings and a one-line STATUS= every second.
  void service_tick(Pipeline& p) {
    if (notify_ == nullptr) return;
    const auto now = Clock::now();
    const NotifyPacer::Due due = pacer_.poll(now);
    if (due.watchdog) notify_->watchdog();
    if (!due.status) return;
    const std::int64_t seen = p.intake().stats().frames_seen;
    const double dt = std::chrono::duration<double>(now - status_time_).count();
    const double rate = dt > 0.0 ? static_cast<double>(seen - frames_at_status_) / dt : 0.0;
    frames_at_status_ = seen;
    status_time_ = now;
    std::string detail;
    for (const auto& [reason, n] : p.intake().rejects().all()) {
      detail += (detail.empty() ? "" : " ") + reason + "=" + std::to_string(n);
    }
    const auto& est = p.processor().estimator();
    const std::string extra = !waiting_for_.empty() ? waiting_for_
                              : est.converged()     ? "alpha " + std::to_string(est.alpha())
                                                    : "estimating";
    notify_->status(format_service_status(options_.iface, rate, p.intake().rejects().total(), detail, extra));
  }

  // SO_MEMINFO once per this many reads (~1 s at a saturated bus) and at every timeout.
  static constexpr int kReadsPerDropRefresh = 8192;
  static constexpr auto kMaxBackoff = std::chrono::milliseconds(5000);

  const LiveOptions& options_;
  const std::function<Pipeline&()>& current_;
  std::ostream& err_;
  SocketCanOptions so_;
  WakePlanner planner_;
  std::optional<SplitWakeSource> source_;
  std::optional<LinkMonitor> link_;
  SdNotifier* notify_;
  NotifyPacer pacer_;
  std::uint64_t drops_before_ = 0;    // kernel drops counted by sources already closed
  std::uint64_t drops_reported_ = 0;
  const Pipeline* wired_ = nullptr;   // the pipeline that was told the wake IDs
  std::uint64_t silences_seen_ = 0;   // SplitWakeSource::waking_silences() acted on
  int reads_since_refresh_ = 0;
  std::chrono::milliseconds backoff_{250};
  bool reported_down_ = false;
  bool announced_ready_ = false;
  std::int64_t frames_at_status_ = 0;
  Clock::time_point status_time_ = Clock::now();
  std::string waiting_for_;  // non-empty while the interface cannot be opened
};

}  // namespace

void run_live(const LiveOptions& options, const std::function<Pipeline&()>& current,
              const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err) {
  LiveReader(options, current, err).run(on_reload, flags);
}

}  // namespace resolver
