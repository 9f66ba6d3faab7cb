#include "daemon/decode/sample_joiner.h"

namespace resolver {

namespace {
// Two whole periods with the same slot set are enough to trust it for early emission.
constexpr int kPeriodsToLearn = 2;
}  // namespace

SampleJoiner::SampleJoiner(Emit emit, Lost lost, int window)
    : emit_(std::move(emit)), lost_(std::move(lost)), window_(std::clamp(window, 1, kMaxWindow)) {}

JoinResult SampleJoiner::add(const DecodedPart& part) {
  const std::uint32_t bit = 1U << static_cast<unsigned>(part.slot);
  const auto slot = static_cast<std::size_t>(part.slot);
  JoinResult result = JoinResult::kAccepted;
  std::int64_t index = 0;
  if (!have_index_) {
    have_index_ = true;
    newest_index_ = next_out_ = next_settled_ = index = part.counter;
    newest_counter_ = part.counter;
    out_in_sequence_ = false;
  } else {
    const int step = counter_step(part.counter);
    if (step > window_ || step < -window_) {
      // A new sequence: what is open goes out, and the index goes on as far as the
      // u8 counter counts forward (the sample clock judges that step against time).
      drain(true);
      settle(true);
      missing_.fill(0);  // a gap across a new sequence is not a count of lost frames
      resync_step_ = static_cast<std::uint8_t>(part.counter - newest_counter_);
      newest_index_ += resync_step_;
      newest_counter_ = part.counter;
      next_out_ = next_settled_ = index = newest_index_;
      out_in_sequence_ = false;
      result = JoinResult::kResync;
    } else {
      index = newest_index_ + step;
      if (step > 0) {
        newest_index_ = index;
        newest_counter_ = part.counter;
      } else if (step < 0) {
        result = JoinResult::kReordered;
      }
    }
  }
  Period& p = period(index);
  const bool known = p.index == index && p.state != State::kFree;
  if (known && (p.sample.slots_present & bit) != 0) {
    return (has_last_ & bit) != 0 && last_counter_[slot] == part.counter ? JoinResult::kRepeated : JoinResult::kDuplicate;
  }
  if (index < next_out_) {
    if (out_in_sequence_) {
      if (known) p.late |= bit;
      return JoinResult::kLate;
    }
    next_out_ = next_settled_ = index;  // nothing of this sequence is out yet: it starts before its first frame
  }
  if (!known) {
    p.index = index;
    p.state = State::kOpen;
    p.sample = BenchSample{};
    p.sample.has_counter = true;
    p.sample.counter = part.counter;
    p.sample.index = index;
    p.sample.timestamp_us = part.timestamp_us;
  }
  BenchSample& s = p.sample;
  s.timestamp_us = std::min(s.timestamp_us, part.timestamp_us);
  s.slots_present |= bit;
  seen_slots_ |= bit;
  last_counter_[slot] = part.counter;
  has_last_ |= bit;
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if ((part.roles & (1U << r)) != 0) s.values[r] = part.values[r];
  }
  s.roles = static_cast<std::uint16_t>(s.roles | part.roles);
  drain(false);
  return result;
}

void SampleJoiner::drain(bool all) {
  while (have_index_ && next_out_ <= newest_index_) {
    Period& p = period(next_out_);
    const bool open = p.index == next_out_ && p.state == State::kOpen;
    if (!all && newest_index_ - next_out_ <= window_) {
      // Still inside the window: out only when whole (and the set of slots is known).
      if (!open || learned_periods_ < kPeriodsToLearn ||
          (p.sample.slots_present & expected_slots_) != expected_slots_) {
        break;
      }
    }
    if (open) {
      emit(p);
    } else {
      // No frame of this period came: skipped.
      p.index = next_out_;
      p.state = State::kOut;
      p.sample = BenchSample{};
      p.sample.index = next_out_;
      p.sample.counter = static_cast<std::uint8_t>(next_out_ & 0xFF);
      p.sample.slots_expected = expected_slots_;
      p.late = 0;
    }
    ++next_out_;
    out_in_sequence_ = true;
  }
  settle(false);
}

void SampleJoiner::emit(Period& p) {
  BenchSample& s = p.sample;
  if (learned_periods_ < kPeriodsToLearn) {
    // Learning: the expected set is every slot seen so far.
    if (s.slots_present == seen_slots_) ++learned_periods_;
    expected_slots_ = seen_slots_;
  } else {
    // A slot that appears later (e.g. a reference encoder switched on) joins the set.
    expected_slots_ |= seen_slots_;
  }
  s.slots_expected = expected_slots_;
  p.state = State::kOut;
  p.late = 0;
  emit_(s);
}

void SampleJoiner::settle(bool all) {
  while (next_settled_ < next_out_ && (all || newest_index_ - next_settled_ >= kMaxWindow)) {
    const Period& p = period(next_settled_++);
    const std::uint32_t came = p.sample.slots_present | p.late;
    const std::uint32_t expected = p.sample.slots_expected;
    for (std::size_t slot = 0; slot < missing_.size() && (expected >> slot) != 0; ++slot) {
      const std::uint32_t bit = 1U << slot;
      if ((expected & bit) == 0) continue;
      if ((came & bit) == 0) {
        ++missing_[slot];
      } else if (missing_[slot] > 0) {
        if (lost_) lost_(static_cast<int>(slot), missing_[slot], p.sample);
        missing_[slot] = 0;
      }
    }
  }
}

bool SampleJoiner::note_late(const DecodedPart& part) {
  if (!have_index_) return true;
  const std::int64_t index = newest_index_ + counter_step(part.counter);
  Period& p = period(index);
  if (p.index != index || p.state != State::kOut || index < next_settled_) return true;
  const std::uint32_t bit = 1U << static_cast<unsigned>(part.slot);
  if ((p.sample.slots_present & bit) != 0) return false;
  p.late |= bit;
  return true;
}

void SampleJoiner::flush() {
  drain(true);
  settle(true);
}

void SampleJoiner::reset() {
  for (Period& p : ring_) p.state = State::kFree;
  have_index_ = false;
  seen_slots_ = 0;
  expected_slots_ = 0;
  learned_periods_ = 0;
  has_last_ = 0;
  missing_.fill(0);
}

}  // namespace resolver
