#include "daemon/decode/leading_frame_joiner.h"

#include <array>

namespace resolver {

namespace {
constexpr std::size_t kMaxSlots = 32;  // slots_present is a u32 mask
}  // namespace

JoinResult LeadingFrameJoiner::add(const DecodedPart& part) {
  if (leading_slot_ < 0) {
    pending_.push_back(part);
    if (pending_.size() >= kLearnParts) finish_learning();
  } else {
    group(part);
  }
  return JoinResult::kAccepted;
}

void LeadingFrameJoiner::finish_learning() {
  if (pending_.empty()) return;
  // Mean time gap [us] before each message's frames: the leading message's
  // frames follow the gap between control periods, the others follow it closely.
  std::array<double, kMaxSlots> gap_sum{};
  std::array<int, kMaxSlots> gap_count{};
  for (std::size_t i = 1; i < pending_.size(); ++i) {
    const auto slot = static_cast<std::size_t>(pending_[i].slot) % kMaxSlots;
    gap_sum[slot] += static_cast<double>(pending_[i].timestamp_us - pending_[i - 1].timestamp_us);
    ++gap_count[slot];
  }
  leading_slot_ = pending_.front().slot;  // ties (evenly spaced frames): the first message of the log
  double best = -1.0;
  for (std::size_t s = 0; s < kMaxSlots; ++s) {
    if (gap_count[s] == 0) continue;
    const double mean = gap_sum[s] / gap_count[s];
    if (mean > best) {
      best = mean;
      leading_slot_ = static_cast<int>(s);
    }
  }
  for (const DecodedPart& p : pending_) seen_slots_ |= 1U << static_cast<unsigned>(p.slot);
  std::vector<DecodedPart> parts = std::move(pending_);
  pending_.clear();
  for (const DecodedPart& p : parts) group(p);
}

void LeadingFrameJoiner::group(const DecodedPart& part) {
  const std::uint32_t bit = 1U << static_cast<unsigned>(part.slot);
  if (open_ && (part.slot == leading_slot_ || (sample_.slots_present & bit) != 0)) emit_open();
  if (!open_) {
    open_ = true;
    sample_ = BenchSample{};
    sample_.timestamp_us = part.timestamp_us;
    sample_.index = next_index_++;
    sample_.counter = static_cast<std::uint8_t>(sample_.index & 0xFF);
  }
  sample_.slots_present |= bit;
  seen_slots_ |= bit;
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if ((part.roles & (1U << r)) != 0) sample_.values[r] = part.values[r];
  }
  sample_.roles = static_cast<std::uint16_t>(sample_.roles | part.roles);
  if ((sample_.slots_present & seen_slots_) == seen_slots_) emit_open();
}

void LeadingFrameJoiner::emit_open() {
  if (!open_) return;
  open_ = false;
  sample_.slots_expected = seen_slots_;
  emit_(sample_);
}

void LeadingFrameJoiner::flush() {
  if (leading_slot_ < 0) finish_learning();
  emit_open();
}

void LeadingFrameJoiner::reset() {
  pending_.clear();
  leading_slot_ = -1;
  open_ = false;
  seen_slots_ = 0;
  next_index_ = 0;
}

}  // namespace resolver
