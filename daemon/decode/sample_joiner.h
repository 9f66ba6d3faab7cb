// Joins the decoded parts of one control period (same u8 counter) into a
// BenchSample, in counter order, over a reorder window.
//
// Frames of neighbouring periods can arrive out of order: a USB-CAN adapter's
// buffering, or a reader with several queues, shuffles them by a few
// milliseconds. Every period up to `window` ([layout] max_counter_delta) periods
// behind the newest counter stays open, so a frame that comes after a frame of a
// later period still joins its own sample (counted as reordered, not lost), and
// samples come out in counter order:
//   - as soon as every slot the stream carries has arrived and every earlier
//     sample is out (low latency; enabled once the set of slots has been learned
//     from two whole periods), or
//   - when the newest counter is more than `window` periods ahead of it: what has
//     not arrived by then is missing (the sample is emitted incomplete, counted,
//     never merged with a neighbour), or
//   - on flush() at the end of a log.
// A period without any frame is skipped (its index is not emitted). Until the
// first period of a sequence goes out, a frame within the window before the
// first one opens an earlier period (the stream may start with a reordered frame).
//
// Frames lost are what is missing from the log, never more: a period is settled
// once the newest counter is kMaxWindow periods past it (no frame of it can come
// any more) or at the end; a slot missing from consecutive settled periods is one
// gap, counted through `Lost` when the slot comes back (slot, frames missing, the
// sample it came back in). A frame that came after its sample went out (late,
// dropped) is not lost, and a message that stops is not counted lost at all.
//
// A part whose counter lies outside the window of the newest one starts a new
// sequence (kResync): the periods still open are emitted first and the index
// advances as far as the u8 counter counts forward. Callers decide whether an
// out-of-window part is a new sequence or a stray frame (in_window()) before
// adding it. A second part for a slot already in its period's sample is a
// duplicate and is dropped (counted by the caller), so a repeated frame never
// overwrites good data.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>

#include "daemon/decode/frame_decoder.h"

namespace resolver {

struct BenchSample {
  std::int64_t timestamp_us = 0;  ///< [us] timestamp of the sample's earliest part
  std::int64_t index = 0;         ///< counter unwrapped over 256 (gaps advance it), else a running count
  bool has_counter = false;       ///< index comes from a counter (the sample clock may count on it)
  std::uint8_t counter = 0;
  std::uint16_t roles = 0;        ///< role_bit() mask of valid values
  std::array<double, kRoleCount> values{};
  std::uint32_t slots_present = 0;
  std::uint32_t slots_expected = 0;
  [[nodiscard]] bool has(Role r) const { return (roles & role_bit(r)) != 0; }
  [[nodiscard]] double get(Role r) const { return values[static_cast<std::size_t>(r)]; }
  [[nodiscard]] bool complete() const { return (slots_present & slots_expected) == slots_expected; }
};

enum class JoinResult : std::uint8_t {
  kAccepted,   ///< joined its period's sample
  kReordered,  ///< joined its period's sample after a frame of a later period had come
  kRepeated,   ///< the slot's previous part again (same counter): dropped
  kDuplicate,  ///< its slot is already in its period's sample: dropped
  kLate,       ///< its period's sample is out already: dropped
  kResync,     ///< outside the window: a new sequence starts with it (resync_step() says how far)
};

class SampleJoiner {
 public:
  using Emit = std::function<void(const BenchSample&)>;
  /// A slot missing from `frames` consecutive periods came back in `sample`.
  using Lost = std::function<void(int slot, std::int64_t frames, const BenchSample& sample)>;
  /// Counters further apart than this cannot be told from a wrap of the u8 counter.
  static constexpr int kMaxWindow = 127;

  /// `window`: periods a sample waits for its frames behind the newest counter
  /// ([layout] max_counter_delta; clamped to 1..kMaxWindow).
  SampleJoiner(Emit emit, Lost lost, int window = 8);

  /// Adds a part; may emit samples through the callback.
  JoinResult add(const DecodedPart& part);
  /// True when `counter` is within the window of the newest counter (or nothing came yet).
  [[nodiscard]] bool in_window(std::uint8_t counter) const {
    const int step = counter_step(counter);
    return !have_index_ || (step <= window_ && step >= -window_);
  }
  /// Periods from the newest counter to `counter`, in -128..127.
  [[nodiscard]] int counter_step(std::uint8_t counter) const {
    return static_cast<std::int8_t>(static_cast<std::uint8_t>(counter - newest_counter_));
  }
  [[nodiscard]] std::uint8_t newest_counter() const { return newest_counter_; }
  /// True when `part`'s period (within the window) holds its slot already.
  [[nodiscard]] bool has_slot(const DecodedPart& part) const {
    const std::int64_t index = newest_index_ + counter_step(part.counter);
    const Period& p = ring_[static_cast<std::size_t>(index) % kRing];
    return have_index_ && p.index == index && p.state != State::kFree &&
           (p.sample.slots_present & (1U << static_cast<unsigned>(part.slot))) != 0;
  }
  /// kResync: how far the index advanced (as far as the u8 counter counts forward, 1..255).
  [[nodiscard]] int resync_step() const { return resync_step_; }
  [[nodiscard]] int window() const { return window_; }
  /// A new window (config reload); call reset() with it.
  void set_window(int window) { window_ = std::clamp(window, 1, kMaxWindow); }
  /// A part the caller dropped as late (its counter behind the window): recorded so
  /// the settled period does not count it lost. False when its slot is already in
  /// that period's sample (a duplicate, not a late frame).
  bool note_late(const DecodedPart& part);
  /// Emits every open sample and settles every period (end of log, shutdown).
  void flush();
  /// Forgets everything (e.g. between passes of a looped log).
  void reset();

 private:
  enum class State : std::uint8_t { kFree, kOpen, kOut };
  struct Period {
    std::int64_t index = -1;
    State state = State::kFree;
    BenchSample sample;       ///< kOpen: the sample so far; kOut: as emitted (slots_present 0: skipped)
    std::uint32_t late = 0;   ///< kOut: slots whose frame came after the sample went out
  };
  static constexpr std::size_t kRing = 256;  // one period per u8 counter value

  Period& period(std::int64_t index) { return ring_[static_cast<std::size_t>(index) % kRing]; }
  /// Emits (or skips) the oldest periods while they are complete, out of the window, or `all`.
  void drain(bool all);
  void emit(Period& p);
  /// Gap bookkeeping of the periods no frame can reach any more (`all`: every period out).
  void settle(bool all);
  Emit emit_;
  Lost lost_;
  int window_;
  std::array<Period, kRing> ring_{};
  bool have_index_ = false;
  std::int64_t newest_index_ = 0;
  std::uint8_t newest_counter_ = 0;
  std::int64_t next_out_ = 0;  ///< the oldest period not emitted or skipped yet
  std::int64_t next_settled_ = 0;  ///< the oldest period out but not settled yet
  bool out_in_sequence_ = false;  ///< a period of this sequence went out (before: a frame may open an earlier one)
  int resync_step_ = 0;
  std::uint32_t seen_slots_ = 0;      ///< every slot seen so far
  std::uint32_t expected_slots_ = 0;  ///< learned set of slots per period
  int learned_periods_ = 0;
  std::array<std::uint8_t, 32> last_counter_{};  ///< per slot: counter of its previous part
  std::uint32_t has_last_ = 0;                   ///< slots with a previous part
  std::array<std::int64_t, 32> missing_{};       ///< per slot: settled periods missing it since it last came
};

}  // namespace resolver
