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

#include "daemon/core/errors.h"
#include "tools/echo/echo_output.h"

namespace resolver {

struct LiveEchoResult {
  std::int64_t emitted = 0;  ///< lines passed to the sink
  bool timed_out = false;    ///< stopped by the timeout, not by the count
};

class LiveEcho {
 public:
  /// Subscribes to all channels of `lcm`. `lcm` and `decoder` must outlive this object.
  LiveEcho(lcm::LCM& lcm, const LcmJsonDecoder& decoder, EchoFilter filter, JsonLineSink sink);
  ~LiveEcho();
  LiveEcho(const LiveEcho&) = delete;
  LiveEcho& operator=(const LiveEcho&) = delete;

  /// Handles messages until `count` more lines were emitted (if given) or
  /// `timeout` elapsed (if given; otherwise waits forever). When LCM or the sink
  /// fails, throws IoError (exit 3) "LCM_AT: what happened" once LCM has returned:
  /// exceptions from the sink are caught inside the LCM callback (they must not
  /// unwind through LCM's C code) and thrown from here. `lcm_at` names the URL
  /// (the option "--lcm URL").
  LiveEchoResult run(std::optional<std::int64_t> count, std::optional<std::chrono::milliseconds> timeout,
                     const Where& lcm_at = {});

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
  std::string error_;  ///< what failed in on_message ("" = nothing)
};

}  // namespace resolver
