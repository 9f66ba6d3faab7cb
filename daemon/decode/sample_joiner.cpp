#include "daemon/decode/sample_joiner.h"

namespace resolver {

namespace {
// Two whole periods with the same slot set are enough to trust it for early emission.
constexpr int kPeriodsToLearn = 2;
}  // namespace

JoinResult SampleJoiner::add(const DecodedPart& part) {
  const std::uint32_t bit = 1U << static_cast<unsigned>(part.slot);
  if (open_ && part.counter == sample_.counter) {
    if ((sample_.slots_present & bit) != 0) return JoinResult::kDuplicate;
  } else if (open_) {
    emit_open();
  }
  if (!open_) {
    open_ = true;
    sample_ = BenchSample{};
    sample_.has_counter = true;
    sample_.counter = part.counter;
    sample_.timestamp_us = part.timestamp_us;
    if (!have_index_) {
      have_index_ = true;
      index_ = part.counter;
    } else {
      index_ += static_cast<std::uint8_t>(part.counter - last_counter_);
    }
    last_counter_ = part.counter;
    sample_.index = index_;
  }
  sample_.slots_present |= bit;
  seen_slots_ |= bit;
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if ((part.roles & (1U << r)) != 0) sample_.values[r] = part.values[r];
  }
  sample_.roles = static_cast<std::uint16_t>(sample_.roles | part.roles);
  if (learned_periods_ >= kPeriodsToLearn && (sample_.slots_present & expected_slots_) == expected_slots_) {
    emit_open();
  }
  return JoinResult::kAccepted;
}

void SampleJoiner::emit_open() {
  if (!open_) return;
  open_ = false;
  if (learned_periods_ < kPeriodsToLearn) {
    // Learning: the expected set is every slot seen so far.
    if (sample_.slots_present == seen_slots_) ++learned_periods_;
    expected_slots_ = seen_slots_;
  } else {
    // A slot that appears later (e.g. a reference encoder switched on) joins the set.
    expected_slots_ |= seen_slots_;
  }
  sample_.slots_expected = expected_slots_;
  emit_(sample_);
}

void SampleJoiner::flush() { emit_open(); }

void SampleJoiner::reset() {
  open_ = false;
  seen_slots_ = 0;
  expected_slots_ = 0;
  learned_periods_ = 0;
  have_index_ = false;
}

}  // namespace resolver
