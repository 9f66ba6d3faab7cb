#include "daemon/app/wake_planner.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

namespace resolver {

WakePlanner::WakePlanner(bool auto_mode, std::vector<std::uint32_t> fixed)
    : auto_mode_(auto_mode), current_(auto_mode ? std::vector<std::uint32_t>{} : std::move(fixed)) {}

bool WakePlanner::wakes(std::uint32_t id) const {
  return current_.empty() || std::find(current_.begin(), current_.end(), id) != current_.end();
}

std::optional<std::vector<std::uint32_t>> WakePlanner::on_sample_completed_by(std::uint32_t id) {
  if (!auto_mode_) return std::nullopt;
  if (current_.empty()) {
    streak_ = id == streak_id_ ? streak_ + 1 : 1;
    streak_id_ = id;
    if (streak_ >= kLearnSamples) return std::vector<std::uint32_t>{id};
    return std::nullopt;
  }
  not_waking_ = wakes(id) ? 0 : not_waking_ + 1;
  if (not_waking_ >= kFallbackSamples) return std::vector<std::uint32_t>{};
  return std::nullopt;
}

std::optional<std::vector<std::uint32_t>> WakePlanner::on_waking_silence() {
  if (!auto_mode_ || current_.empty()) return std::nullopt;
  return std::vector<std::uint32_t>{};
}

void WakePlanner::switched(std::vector<std::uint32_t> ids) {
  current_ = std::move(ids);
  streak_ = 0;
  not_waking_ = 0;
}

std::string WakePlanner::describe(const std::vector<std::uint32_t>& ids) {
  if (ids.empty()) return "every frame";
  std::string out;
  for (const std::uint32_t id : ids) out += fmt::format("{}0x{:X}", out.empty() ? "" : ", ", id);
  return out;
}

}  // namespace resolver
