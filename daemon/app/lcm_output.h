// OutputSink that publishes on LCM with the configured channel names.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "daemon/app/daemon_config.h"
#include "daemon/app/output_sink.h"

namespace resolver {

class LcmOutput final : public OutputSink {
 public:
  /// Opens LCM on `url` ("" = LCM's default). Throws std::runtime_error when
  /// LCM cannot be initialised (bad URL, no multicast route).
  LcmOutput(const std::string& url, LcmChannels channels);

  void publish(const angle_t& msg) override { send(channels_.angle, msg); }
  void publish(const dq_t& msg) override { send(channels_.dq, msg); }
  void publish(const estimate_t& msg) override { send(channels_.estimate, msg); }
  void publish(const model_fit_t& msg) override { send(channels_.model_fit, msg); }
  void publish(const health_t& msg) override { send(channels_.health, msg); }

  /// Messages LCM refused to send (publish returned non-zero).
  [[nodiscard]] std::uint64_t publish_failures() const { return failures_; }
  [[nodiscard]] std::uint64_t published() const { return published_; }
  lcm::LCM& lcm() { return lcm_; }

 private:
  template <typename T>
  void send(const std::string& channel, const T& msg) {
    if (lcm_.publish(channel, &msg) != 0) {
      ++failures_;
    } else {
      ++published_;
    }
  }

  lcm::LCM lcm_;
  LcmChannels channels_;
  std::uint64_t failures_ = 0;
  std::uint64_t published_ = 0;
};

}  // namespace resolver
