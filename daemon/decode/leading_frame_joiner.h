// Joins the frames of one control period into a BenchSample for a layout
// without a counter ([layout] counter_signal = ""), e.g. a scope export
// converted to CAN: nothing numbers the samples, so frames join by order.
//
// One mapped message: every frame is one sample. Several: a control period's
// frames arrive together and a gap separates periods, so a sample runs from a
// frame of the *leading* message (the one whose frames follow the longest
// gaps, learned from the first kLearnParts frames, which wait until then) to
// the next. A sample is emitted as soon as every message the stream carries has
// arrived, when the next leading frame comes, or when a message repeats (its
// leading frame was lost); one that misses a message is incomplete (the caller
// counts it). No time threshold is involved, so bursty delivery (USB adapters,
// canplayer) cannot split a sample. Gaps between samples are found from time by
// the sample clock (sample_clock.h).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "daemon/decode/sample_joiner.h"

namespace resolver {

class LeadingFrameJoiner {
 public:
  /// Frames the leading message is learned from.
  static constexpr std::size_t kLearnParts = 32;
  using Emit = std::function<void(const BenchSample&)>;
  explicit LeadingFrameJoiner(Emit emit) : emit_(std::move(emit)) {}

  /// Adds a part; may emit samples through the callback. Never a duplicate:
  /// a repeated message starts the next sample.
  JoinResult add(const DecodedPart& part);
  /// Emits what is pending or open (end of input).
  void flush();
  /// Forgets everything (e.g. between passes of a looped log).
  void reset();

 private:
  void finish_learning();
  void group(const DecodedPart& part);
  void emit_open();

  Emit emit_;
  std::vector<DecodedPart> pending_;  ///< parts waiting while the leading message is learned
  int leading_slot_ = -1;             ///< -1 while learning
  bool open_ = false;
  BenchSample sample_;
  std::uint32_t seen_slots_ = 0;
  std::int64_t next_index_ = 0;
};

}  // namespace resolver
