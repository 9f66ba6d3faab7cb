#include "daemon/service/sd_notify.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <utility>

namespace resolver {

namespace {

/// Parses a decimal unsigned environment value; nullopt-like 0 when absent or bad.
std::uint64_t parse_u64(const char* text) {
  if (text == nullptr || *text == '\0') return 0;
  std::uint64_t value = 0;
  const char* end = text + std::strlen(text);
  const auto [ptr, ec] = std::from_chars(text, end, value);
  if (ec != std::errc{} || ptr != end) return 0;
  return value;
}

/// Fills `addr` for "/path" or "@abstract"; returns the address length or 0
/// with `problem` set.
socklen_t make_address(std::string_view address, sockaddr_un& addr, std::string& problem) {
  std::memset(&addr, 0, sizeof addr);
  addr.sun_family = AF_UNIX;
  if (address.empty() || (address.front() != '/' && address.front() != '@')) {
    problem = "NOTIFY_SOCKET '" + std::string(address) +
              "' is neither an absolute path nor an '@' abstract name; systemd notifications are off "
              "(start resolverd from its unit or unset NOTIFY_SOCKET)";
    return 0;
  }
  // Abstract names have no terminating NUL; paths keep room for one.
  const std::size_t room = sizeof addr.sun_path - (address.front() == '/' ? 1 : 0);
  if (address.size() > room) {
    problem = "NOTIFY_SOCKET '" + std::string(address) + "' is longer than an AF_UNIX address (" +
              std::to_string(room) + " bytes); systemd notifications are off";
    return 0;
  }
  std::memcpy(addr.sun_path, address.data(), address.size());
  if (address.front() == '@') addr.sun_path[0] = '\0';
  return static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + address.size());
}

std::int64_t monotonic_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + static_cast<std::int64_t>(ts.tv_nsec) / 1000;
}

}  // namespace

SdNotifier SdNotifier::from_environment() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  if (socket == nullptr || *socket == '\0') return SdNotifier{};
  auto period = std::chrono::microseconds(static_cast<std::int64_t>(parse_u64(std::getenv("WATCHDOG_USEC"))));
  const std::uint64_t watchdog_pid = parse_u64(std::getenv("WATCHDOG_PID"));
  if (watchdog_pid != 0 && watchdog_pid != static_cast<std::uint64_t>(::getpid())) {
    period = std::chrono::microseconds(0);  // the watchdog belongs to another process
  }
  return SdNotifier(socket, period);
}

SdNotifier::SdNotifier(std::string_view socket_address, std::chrono::microseconds watchdog_period)
    : address_(socket_address), watchdog_period_(watchdog_period) {
  sockaddr_un addr{};
  if (make_address(address_, addr, last_error_) == 0) return;
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    last_error_ = "cannot create the AF_UNIX datagram socket for NOTIFY_SOCKET '" + address_ +
                  "': " + std::strerror(errno) + "; systemd notifications are off";
  }
}

SdNotifier::~SdNotifier() { close_socket(); }

SdNotifier::SdNotifier(SdNotifier&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      address_(std::move(other.address_)),
      watchdog_period_(other.watchdog_period_),
      last_error_(std::move(other.last_error_)),
      send_failures_(other.send_failures_) {}

SdNotifier& SdNotifier::operator=(SdNotifier&& other) noexcept {
  if (this != &other) {
    close_socket();
    fd_ = std::exchange(other.fd_, -1);
    address_ = std::move(other.address_);
    watchdog_period_ = other.watchdog_period_;
    last_error_ = std::move(other.last_error_);
    send_failures_ = other.send_failures_;
  }
  return *this;
}

void SdNotifier::close_socket() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SdNotifier::send(std::string_view message) {
  if (fd_ < 0) return false;
  sockaddr_un addr{};
  std::string problem;
  const socklen_t len = make_address(address_, addr, problem);
  ssize_t sent = -1;
  do {
    sent = ::sendto(fd_, message.data(), message.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&addr), len);
  } while (sent < 0 && errno == EINTR);
  if (sent < 0 || static_cast<std::size_t>(sent) != message.size()) {
    ++send_failures_;
    last_error_ = "cannot send '" + std::string(message.substr(0, message.find('\n'))) + "' to NOTIFY_SOCKET '" +
                  address_ + "': " + (sent < 0 ? std::strerror(errno) : "short send") +
                  "; is systemd (or the test's listener) still there?";
    return false;
  }
  return true;
}

void SdNotifier::ready() { send("READY=1"); }

void SdNotifier::reloading() { send("RELOADING=1\nMONOTONIC_USEC=" + std::to_string(monotonic_us())); }

void SdNotifier::stopping() { send("STOPPING=1"); }

void SdNotifier::status(std::string_view text) {
  std::string message = "STATUS=";
  message.append(text);
  for (std::size_t i = 7; i < message.size(); ++i) {
    if (message[i] == '\n' || message[i] == '\r') message[i] = ' ';
  }
  send(message);
}

void SdNotifier::watchdog() { send("WATCHDOG=1"); }

std::chrono::microseconds SdNotifier::watchdog_interval() const {
  if (fd_ < 0) return std::chrono::microseconds(0);
  return watchdog_period_ / 2;
}

NotifyPacer::NotifyPacer(std::chrono::microseconds watchdog_interval, std::chrono::microseconds status_period)
    : watchdog_interval_(watchdog_interval), status_period_(status_period) {}

NotifyPacer::Due NotifyPacer::poll(Clock::time_point now) {
  Due due;
  if (!started_) {
    // The first turn sends both: the watchdog clock starts with READY=1.
    started_ = true;
    due.watchdog = watchdog_interval_.count() > 0;
    due.status = status_period_.count() > 0;
    last_watchdog_ = now;
    last_status_ = now;
    return due;
  }
  if (watchdog_interval_.count() > 0 && now - last_watchdog_ >= watchdog_interval_) {
    due.watchdog = true;
    last_watchdog_ = now;
  }
  if (status_period_.count() > 0 && now - last_status_ >= status_period_) {
    due.status = true;
    last_status_ = now;
  }
  return due;
}

std::string format_service_status(std::string_view iface, double frame_rate_hz, std::int64_t rejected,
                                  std::string_view rejects_detail, std::string_view extra) {
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.1f", frame_rate_hz);
  std::string out(iface);
  out += ": ";
  out += rate;
  out += " frames/s, ";
  out += std::to_string(rejected);
  out += " rejected";
  if (!rejects_detail.empty()) {
    out += " (";
    out += rejects_detail;
    out += ')';
  }
  if (!extra.empty()) {
    out += ", ";
    out += extra;
  }
  return out;
}

}  // namespace resolver
