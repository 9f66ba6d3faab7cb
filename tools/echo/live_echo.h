// Live mode: subscribe to every channel of an LCM instance and turn each
// message into a JSON line, until a count or a timeout is reached.
//
// Runs on the caller's thread (run() calls lcm.handleTimeout); no thread of its
// own. The LCM handle is passed in so tests can use memq://. The subscription
// exists from construction on: memq:// (and LCM generally) drops messages
// published while nobody is subscribed.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "tools/echo/echo_output.h"

namespace resolver {

struct LiveEchoResult {
  std::int64_t emitted = 0;  ///< lines passed to the sink
  bool timed_out = false;    ///< stopped by the timeout, not by the count
  std::string error;         ///< non-empty when LCM or the sink failed; what happened
};

class LiveEcho {
 public:
  /// Subscribes to all channels of `lcm`. `lcm` and `decoder` must outlive this object.
  LiveEcho(lcm::LCM& lcm, const LcmJsonDecoder& decoder, EchoFilter filter, JsonLineSink sink);
  ~LiveEcho();
  LiveEcho(const LiveEcho&) = delete;
  LiveEcho& operator=(const LiveEcho&) = delete;

  /// Handles messages until `count` more lines were emitted (if given) or
  /// `timeout` elapsed (if given; otherwise waits forever). Never throws:
  /// exceptions from the sink are caught inside the LCM callback (they must not
  /// unwind through LCM's C code) and reported in LiveEchoResult::error.
  LiveEchoResult run(std::optional<std::int64_t> count, std::optional<std::chrono::milliseconds> timeout);

 private:
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LiveEcho* self) noexcept;

  lcm::LCM& lcm_;
  const LcmJsonDecoder& decoder_;
  EchoFilter filter_;
  JsonLineSink sink_;
  lcm::Subscription* subscription_ = nullptr;
  // State of the current run(), written by on_message.
  std::optional<std::int64_t> count_;
  LiveEchoResult result_;
};

}  // namespace resolver
