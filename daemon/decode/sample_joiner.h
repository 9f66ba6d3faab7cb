// Joins the decoded parts of one control period (same u8 counter) into a
// BenchSample.
//
// Parts of one period arrive back to back. A sample is emitted
//   - as soon as every slot that the stream carries has arrived (low latency;
//     enabled once the set of slots has been learned from two whole periods), or
//   - when a part with a different counter arrives (the open sample is emitted
//     as incomplete if a slot is missing: counted, never merged with a
//     neighbour), or
//   - on flush() at the end of a log.
// A second part for a slot already present in the open sample is a duplicate
// and is dropped (counted by the caller), so a repeated frame never
// overwrites good data.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "daemon/decode/frame_decoder.h"

namespace resolver {

struct BenchSample {
  std::int64_t timestamp_us = 0;  ///< [us] timestamp of the sample's first part
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

enum class JoinResult : std::uint8_t { kAccepted, kDuplicate };

class SampleJoiner {
 public:
  using Emit = std::function<void(const BenchSample&)>;
  explicit SampleJoiner(Emit emit) : emit_(std::move(emit)) {}

  /// Adds a part; may emit zero, one or two samples through the callback.
  JoinResult add(const DecodedPart& part);
  /// Emits the open sample, if any (end of log, shutdown).
  void flush();
  /// Forgets everything (e.g. between passes of a looped log).
  void reset();

 private:
  void emit_open();

  Emit emit_;
  bool open_ = false;
  BenchSample sample_;
  std::uint32_t seen_slots_ = 0;      ///< every slot seen so far
  std::uint32_t expected_slots_ = 0;  ///< learned set of slots per period
  int learned_periods_ = 0;
  bool have_index_ = false;
  std::int64_t index_ = 0;
  std::uint8_t last_counter_ = 0;
};

}  // namespace resolver
