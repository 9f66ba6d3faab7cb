#include "tools/echo/live_echo.h"

#include <algorithm>
#include <exception>

#include <fmt/format.h>

namespace resolver {

LiveEcho::LiveEcho(lcm::LCM& lcm, const LcmJsonDecoder& decoder, EchoFilter filter, JsonLineSink sink)
    : lcm_(lcm), decoder_(decoder), filter_(std::move(filter)), sink_(std::move(sink)) {
  // Subscribe to everything and filter with std::regex, so --channel means the
  // same in live and log mode.
  if (lcm_.good()) subscription_ = lcm_.subscribeFunction(".*", &LiveEcho::on_message, this);
}

LiveEcho::~LiveEcho() {
  if (subscription_ != nullptr) lcm_.unsubscribe(subscription_);
}

void LiveEcho::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LiveEcho* self) noexcept {
  LiveEchoResult& result = self->result_;
  if (!self->error_.empty() || (self->count_ && result.emitted >= *self->count_)) return;
  try {
    const std::span<const std::uint8_t> data(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size);
    const auto line = format_message_json(self->decoder_, self->filter_, channel, rbuf->recv_utime, data);
    if (!line) return;
    self->sink_(*line);
    ++result.emitted;
  } catch (const std::exception& e) {
    self->error_ = fmt::format("channel '{}': cannot output the message: {}", channel, e.what());
  } catch (...) {
    self->error_ = fmt::format("channel '{}': cannot output the message (unknown exception)", channel);
  }
}

LiveEchoResult LiveEcho::run(std::optional<std::int64_t> count, std::optional<std::chrono::milliseconds> timeout,
                             const Where& lcm_at) {
  result_ = {};
  error_.clear();
  count_ = count;
  if (subscription_ == nullptr) {
    throw IoError("the LCM instance failed to initialize; check the --lcm URL and the network (multicast route)",
                  lcm_at);
  }
  using Clock = std::chrono::steady_clock;
  const auto deadline = timeout ? std::optional(Clock::now() + *timeout) : std::nullopt;
  while (error_.empty() && !(count_ && result_.emitted >= *count_)) {
    // Wake at least every 100 ms so the deadline is honoured.
    int wait_ms = 100;
    if (deadline) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - Clock::now()).count();
      if (left <= 0) {
        result_.timed_out = true;
        break;
      }
      wait_ms = static_cast<int>(std::min<long long>(left, wait_ms));
    }
    if (lcm_.handleTimeout(wait_ms) < 0) {
      error_ = "LCM reported an error while receiving; check the --lcm URL";
    }
  }
  if (!error_.empty()) throw IoError(error_, lcm_at);
  return result_;
}

}  // namespace resolver
