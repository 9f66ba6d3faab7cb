// Front half of the pipeline: CAN frames in, joined bench samples out.
//
//   frame ─► another interface than the one read? ─► other_interface (per interface)
//         └► error frame? ─► bus_errors
//         └► FrameDecoder (ID, DLC, CRC, units) ─► reject counters
//              └► counter outside the reorder window? held until the next frames say
//                 whether a new sequence starts with it or it was a stray (late) frame
//                   └► SampleJoiner (reorder window, repeated / reordered / late,
//                      frames lost as the gaps samples leave) ─► on_sample(BenchSample)
//              └► (layout without a counter) LeadingFrameJoiner ─► on_sample
//   BENCH_INFO ─► on_bench_info(BenchInfo)
//
// No I/O: problems are reported through the Diagnostics callback with a
// message that names the frame (and log line when the caller knows it).
//
// One interface: a log can hold several buses (candump -l any, two benches on
// can0 and can1, the same frames seen on both). Their counters are unrelated, so
// joining them made one nonsense stream (counter jumps read as hundreds of seconds
// of a standing rotor). The frames of the first interface that carries a frame of
// the layout are read; every other interface's are counted (other_interface, and
// per interface in interfaces()) and left out, the first of each with a message
// that says how to read it instead. Frames without an interface name (SocketCAN,
// CSV rows) are always read.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "daemon/decode/frame_decoder.h"
#include "daemon/decode/leading_frame_joiner.h"
#include "daemon/decode/reject_counters.h"
#include "daemon/decode/sample_joiner.h"

namespace resolver {

struct IntakeStats {
  std::int64_t frames_seen = 0;
  std::int64_t frames_decoded = 0;   ///< frames that became part of a sample or a BENCH_INFO
  std::int64_t bus_errors = 0;       ///< CAN error frames
  std::int64_t samples_complete = 0;
  std::int64_t samples_incomplete = 0;
  std::int64_t frames_lost = 0;      ///< frames missing according to counter gaps
};

/// Frames of one CAN interface of a log (CanFrame::iface_name()).
struct InterfaceFrames {
  std::string name;
  std::int64_t frames = 0;    ///< every frame of the interface
  std::int64_t left_out = 0;  ///< of them, counted as other_interface (not the interface read)
  bool read = false;          ///< the interface whose frames are joined
};

class FrameIntake {
 public:
  struct Callbacks {
    std::function<void(const BenchSample&)> on_sample;
    std::function<void(const BenchInfo&)> on_bench_info;
    /// reason (a counter name) and a one-line human message.
    std::function<void(std::string_view reason, const std::string& message)> on_problem;
  };

  FrameIntake(std::shared_ptr<const FrameDecoder> decoder, int max_counter_delta, Callbacks callbacks);

  /// Processes one frame; `line` is the log line (0 when live). Cannot fail.
  void feed(const CanFrame& frame, std::uint64_t line = 0);
  /// A sample that came without frames (a CSV row): counted as one frame seen
  /// and decoded and as one sample, then passed on. Cannot fail.
  void feed_sample(const BenchSample& sample) {
    ++stats_.frames_seen;
    ++stats_.frames_decoded;
    on_joined(sample);
  }
  /// Counts a problem found before decoding (e.g. a malformed log line).
  void count_problem(std::string_view reason, const std::string& message);
  /// Counts a problem the caller has already reported.
  void count_problem_silently(std::string_view reason, std::int64_t n = 1) { rejects_.add(reason, n); }
  /// Emits the sample still open (end of input).
  void flush() {
    drop_held();  // no frames after them to start a sequence with
    joiner_.flush();
    order_joiner_.flush();
  }
  /// Forgets counters and open samples, keeps statistics (e.g. log loop).
  void restart_sequence();
  /// A config reload: decodes with `decoder` from the next frame on. The open sample is
  /// emitted, counters and joins restart (as at a log loop); statistics and rejects stay.
  void change_decoder(std::shared_ptr<const FrameDecoder> decoder, int max_counter_delta);

  [[nodiscard]] const IntakeStats& stats() const { return stats_; }
  [[nodiscard]] const RejectCounters& rejects() const { return rejects_; }
  [[nodiscard]] const FrameDecoder& decoder() const { return *decoder_; }
  [[nodiscard]] std::shared_ptr<const FrameDecoder> decoder_ptr() const { return decoder_; }
  /// Counter of the last frame decoded (valid once one was).
  [[nodiscard]] std::uint8_t last_frame_counter() const { return part_.counter; }
  /// Every interface named by a frame so far, in order of appearance (empty live).
  [[nodiscard]] const std::vector<InterfaceFrames>& interfaces() const { return interfaces_; }
  /// With frames of more than one interface: one sentence naming each with its frames,
  /// which was read and how to read another; "" otherwise.
  [[nodiscard]] std::string interface_note() const;

 private:
  void reject(std::string_view reason, const CanFrame& frame, std::uint64_t line, const std::string& detail);
  /// A part of a layout with a counter: held, joined or dropped (see the drawing above).
  void feed_counted(const CanFrame& frame, std::uint64_t line);
  /// Joins `part` (of `frame`, at `line`) and counts what the joiner says of it.
  void join(const DecodedPart& part, const CanFrame& frame, std::uint64_t line);
  /// The held out-of-window frames did not start a sequence: counted and dropped.
  void drop_held();
  /// SampleJoiner: `slot` missing from `frames` periods came back in `sample`.
  void on_lost(int slot, std::int64_t frames, const BenchSample& sample);
  [[nodiscard]] const std::string& slot_name(int slot) const {
    return decoder_->slots()[static_cast<std::size_t>(slot)].message->name;
  }
  /// Counts the frame under its interface; false when it belongs to another interface
  /// than the one read (counted as other_interface, reported once per interface).
  bool from_read_interface(const CanFrame& frame, std::uint64_t line);
  void on_joined(const BenchSample& sample);
  /// The message for a kMuxPageUnmapped reject: switch value and where the roles are.
  [[nodiscard]] std::string mux_page_detail(const CanFrame& frame, std::uint64_t mux_value) const;
  /// Counts (mux_role_absent, one per role) and reports the roles the frame's page lacks.
  void report_absent_roles(const CanFrame& frame, std::uint64_t line);

  std::shared_ptr<const FrameDecoder> decoder_;
  int max_counter_delta_;
  Callbacks callbacks_;
  SampleJoiner joiner_;             ///< layouts with a counter
  LeadingFrameJoiner order_joiner_;  ///< layouts without one
  RejectCounters rejects_;
  IntakeStats stats_;
  DecodedPart part_;
  BenchInfo info_;
  /// Parts whose counter is outside the joiner's window, until the next parts say
  /// whether a new sequence starts with them (joined) or they were strays (dropped):
  /// a frame of the current window drops them; a sequence ahead is confirmed by a
  /// second frame near it, one behind (a restart, logs appended, or frames later than
  /// the window) by 64 frames in a row (feed_counted()).
  struct Held {
    DecodedPart part;
    CanFrame frame;
    std::uint64_t line = 0;
  };
  std::vector<Held> held_;
  std::uint8_t held_newest_ = 0;  ///< the newest counter of the held frames
  std::vector<InterfaceFrames> interfaces_;
  std::size_t last_interface_ = 0;  ///< index into interfaces_ of the previous frame's
  int read_interface_ = -1;         ///< index into interfaces_; -1 until a frame of the layout came
};

/// "frame 100 at (1700000000.123456)": how messages name a frame (ID in hex, time as candump prints it).
std::string describe_frame(const CanFrame& frame);
/// "(1700000000.123456)": a frame or sample time as candump logs print it.
std::string describe_frame_time(std::int64_t timestamp_us);

}  // namespace resolver
