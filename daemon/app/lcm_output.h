// OutputSink that publishes on LCM with the configured channel names.
// A file:///path?mode=w (or mode=a) URL is written by our own buffered LCM log
// writer (lcm_log_writer.h: same file format, ~2x faster replays); every other
// URL (udpm, memq, file with other options) goes through liblcm.
//
// Event times in a log we write are bench time: the message's utime (frame
// time), never the wall clock, so lcm-logplayer replays a --fast replay's log
// at the bench's own speed. A message older than the previous event (model_fit_t
// is published a window late) keeps the previous event's time: players and
// readers expect event times that never go back.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/app/lcm_log_writer.h"

#include "daemon/app/daemon_config.h"
#include "daemon/app/output_sink.h"

namespace resolver {

class LcmOutput final : public OutputSink {
 public:
  /// Opens LCM on `url` ("" = LCM's default). Throws std::system_error when
  /// LCM cannot be initialised (bad URL, no multicast route).
  LcmOutput(const std::string& url, LcmChannels channels);

  void publish(const angle_t& msg) override { send(channels_.angle, msg); }
  void publish(const dq_t& msg) override { send(channels_.dq, msg); }
  void publish(const estimate_t& msg) override { send(channels_.estimate, msg); }
  void publish(const model_fit_t& msg) override { send(channels_.model_fit, msg); }
  /// health_t (1 Hz) also flushes a log file, so a file being written live lags by at most a second.
  void publish(const health_t& msg) override {
    send(channels_.health, msg);
    (void)flush();
  }

  /// Messages LCM refused to send (publish returned non-zero), or that a log
  /// file write lost.
  [[nodiscard]] std::uint64_t publish_failures() const {
    return failures_ + (writer_ ? static_cast<std::uint64_t>(writer_->lost()) : 0U);
  }
  [[nodiscard]] std::uint64_t published() const { return published_; }
  /// Writes out what the log writer buffers (no-op for liblcm URLs). False on a write error.
  bool flush();
  /// Why the last log write failed ("" when none).
  [[nodiscard]] std::string write_error() const { return writer_ ? writer_->error() : std::string(); }

 private:
  template <typename T>
  void send(const std::string& channel, const T& msg) {
    if (writer_) {
      const int size = msg.getEncodedSize();
      last_event_us_ = std::max(last_event_us_, static_cast<std::int64_t>(msg.utime));
      std::uint8_t* data = writer_->begin_event(channel, static_cast<std::size_t>(size), last_event_us_);
      if (msg.encode(data, 0, size) != size) ++failures_;  // cannot happen for our own types; counted anyway
      else ++published_;
      return;
    }
    if (lcm_->publish(channel, &msg) != 0) {
      ++failures_;
    } else {
      ++published_;
    }
  }

  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<LcmLogWriter> writer_;
  LcmChannels channels_;
  std::uint64_t failures_ = 0;
  std::uint64_t published_ = 0;
  std::int64_t last_event_us_ = 0;  ///< [us] event time of the last logged message
};

}  // namespace resolver
