// Sequence-counter supervision per message, in the spirit of AUTOSAR E2E
// profile 1/2 states: the u8 counter of each message should advance by one per
// control period.
//   delta = (counter - last) mod 256
//   0                     -> kRepeated       (same frame again: drop it)
//   1                     -> kOk
//   2 .. max_delta        -> kSomeLost       (delta-1 frames lost, accept)
//   > max_delta           -> kWrongSequence  (resynchronise on this frame, accept)
#pragma once

#include <cstdint>

namespace resolver {

enum class CounterStatus : std::uint8_t { kInitial, kOk, kRepeated, kSomeLost, kWrongSequence };

class CounterCheck {
 public:
  /// max_delta: largest counter step still read as "some frames lost" (AUTOSAR MaxDeltaCounter).
  explicit CounterCheck(int max_delta = 8) : max_delta_(max_delta) {}

  /// Checks a new counter value. Cannot fail.
  CounterStatus check(std::uint8_t counter) {
    if (!started_) {
      started_ = true;
      last_ = counter;
      return CounterStatus::kInitial;
    }
    const int delta = static_cast<std::uint8_t>(counter - last_);
    if (delta == 0) return CounterStatus::kRepeated;
    last_ = counter;
    if (delta == 1) return CounterStatus::kOk;
    if (delta <= max_delta_) {
      lost_ = delta - 1;
      return CounterStatus::kSomeLost;
    }
    return CounterStatus::kWrongSequence;
  }
  /// Frames lost in the last kSomeLost step.
  [[nodiscard]] int lost() const { return lost_; }
  void reset() { started_ = false; }

 private:
  int max_delta_;
  bool started_ = false;
  std::uint8_t last_ = 0;
  int lost_ = 0;
};

}  // namespace resolver
