// systemd service-manager notifications (sd_notify protocol), without libsystemd.
//
// systemd starts a Type=notify service with $NOTIFY_SOCKET set to an AF_UNIX
// datagram socket: a filesystem path ("/run/systemd/notify") or an abstract
// name written with a leading '@'. The service sends newline-separated
// "KEY=VALUE" assignments as one datagram each:
//   READY=1                           startup finished (socket bound, LCM up)
//   RELOADING=1 + MONOTONIC_USEC=...  SIGHUP reload began (systemd >= 253
//                                     needs the timestamp; older ones ignore it)
//   STOPPING=1                        clean shutdown began
//   STATUS=...                        one line shown by `systemctl status`
//   WATCHDOG=1                        keep-alive; due every WATCHDOG_USEC
// With WatchdogSec= set, systemd passes WATCHDOG_USEC (and WATCHDOG_PID) and
// kills the service if no WATCHDOG=1 arrives within that time; we ping at half
// the period so one late loop turn is not fatal.
//
// Outside systemd (no $NOTIFY_SOCKET) every call is a cheap no-op, so the
// daemon calls these unconditionally. Nothing here throws: a failed send is
// remembered in last_error() and counted, because a notification that cannot
// be delivered must never stop the bench from running.
//
// Threading: not synchronised; call from the daemon's main loop only.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace resolver {

class SdNotifier {
 public:
  /// Reads NOTIFY_SOCKET, WATCHDOG_USEC and WATCHDOG_PID from the environment.
  /// A missing NOTIFY_SOCKET gives a disabled notifier. A malformed one (not an
  /// absolute path or '@' name, too long) also gives a disabled notifier whose
  /// last_error() says why. WATCHDOG_PID naming another process disables the
  /// watchdog (it is meant for that process). Cannot fail.
  static SdNotifier from_environment();

  /// Explicit socket address and watchdog period (0 = no watchdog); for tests
  /// and for callers that take the address from elsewhere. Cannot fail; a bad
  /// address gives a disabled notifier with last_error() set.
  SdNotifier(std::string_view socket_address, std::chrono::microseconds watchdog_period);

  /// A disabled notifier: every call does nothing.
  SdNotifier() = default;
  ~SdNotifier();
  SdNotifier(SdNotifier&& other) noexcept;
  SdNotifier& operator=(SdNotifier&& other) noexcept;
  SdNotifier(const SdNotifier&) = delete;
  SdNotifier& operator=(const SdNotifier&) = delete;

  /// True when there is a socket to notify.
  [[nodiscard]] bool enabled() const { return fd_ >= 0; }

  void ready();      ///< "READY=1"
  void reloading();  ///< "RELOADING=1\nMONOTONIC_USEC=<CLOCK_MONOTONIC [us]>"
  void stopping();   ///< "STOPPING=1"
  /// "STATUS=<text>"; newlines in `text` become spaces (one assignment per line).
  void status(std::string_view text);
  void watchdog();   ///< "WATCHDOG=1" (sent even if no period is known)

  /// How often to call watchdog(): half of WATCHDOG_USEC [us]; 0 when systemd
  /// asked for no watchdog (or the notifier is disabled).
  [[nodiscard]] std::chrono::microseconds watchdog_interval() const;

  /// Sends `message` as one datagram. Returns false (and sets last_error())
  /// when disabled or the send fails.
  bool send(std::string_view message);

  /// The last failure, with the socket address and errno text; empty if none.
  [[nodiscard]] const std::string& last_error() const { return last_error_; }
  /// Number of sends that failed since construction.
  [[nodiscard]] std::uint64_t send_failures() const { return send_failures_; }

 private:
  void close_socket();

  int fd_ = -1;
  std::string address_;  ///< as given: "/path" or "@abstract"
  std::chrono::microseconds watchdog_period_{0};
  std::string last_error_;
  std::uint64_t send_failures_ = 0;
};

/// Paces the notifications a main loop sends: WATCHDOG=1 every
/// watchdog_interval(), STATUS= at most once per `status_period`. Pure
/// bookkeeping over the times the caller passes, so it is testable without a
/// clock. Call poll() on every loop turn (the loop must turn at least twice
/// per watchdog period — live_runner's read timeout guarantees that).
class NotifyPacer {
 public:
  using Clock = std::chrono::steady_clock;
  NotifyPacer(std::chrono::microseconds watchdog_interval, std::chrono::microseconds status_period);

  struct Due {
    bool watchdog = false;
    bool status = false;
  };
  /// What is due at `now`; marks it as sent.
  Due poll(Clock::time_point now);

 private:
  std::chrono::microseconds watchdog_interval_;
  std::chrono::microseconds status_period_;
  bool started_ = false;
  Clock::time_point last_watchdog_{};
  Clock::time_point last_status_{};
};

/// One STATUS= line for `systemctl status`, e.g.
/// "can0: 4000.0 frames/s, 12 rejected (crc 10, counter_gap 2), alpha 1.23e-03"
/// frame_rate_hz [frames/s]; `rejects_detail` is appended in parentheses if
/// not empty; `extra` is appended after a comma if not empty.
std::string format_service_status(std::string_view iface, double frame_rate_hz, std::int64_t rejected,
                                   std::string_view rejects_detail, std::string_view extra);

}  // namespace resolver
