#include "tools/sim/speed_profile.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

namespace resolver {

SpeedProfile::SpeedProfile(std::vector<SpeedSegment> segments) : segments_(std::move(segments)) {
  if (segments_.empty()) {
    throw std::invalid_argument("speed profile: no segments; give --rpm with --duration, or --profile rpm:seconds");
  }
  start_s_.reserve(segments_.size() + 1);
  start_angle_.reserve(segments_.size() + 1);
  double t = 0.0;
  double angle = 0.0;
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    const SpeedSegment& s = segments_[i];
    if (!(s.duration_s > 0.0) || !std::isfinite(s.duration_s) || !std::isfinite(s.rpm_start) ||
        !std::isfinite(s.rpm_end)) {
      throw std::invalid_argument(fmt::format(
          "speed profile: segment {} ({} -> {} r/min for {} s) needs a finite duration > 0 s and finite speeds", i + 1,
          s.rpm_start, s.rpm_end, s.duration_s));
    }
    start_s_.push_back(t);
    start_angle_.push_back(angle);
    // Trapezoid rule is exact for a linear speed.
    angle += 0.5 * (rpm_to_rad_s(s.rpm_start) + rpm_to_rad_s(s.rpm_end)) * s.duration_s;
    t += s.duration_s;
  }
  start_s_.push_back(t);
  start_angle_.push_back(angle);
}

std::size_t SpeedProfile::segment_at(double t) const {
  // Last segment whose start is <= t; times before 0 use the first segment.
  const auto it = std::upper_bound(start_s_.begin(), start_s_.end() - 1, t);
  return it == start_s_.begin() ? 0 : static_cast<std::size_t>(it - start_s_.begin()) - 1;
}

double SpeedProfile::omega_m(double t) const {
  if (t >= duration()) return rpm_to_rad_s(segments_.back().rpm_end);
  const std::size_t i = segment_at(t);
  const SpeedSegment& s = segments_[i];
  const double tau = t - start_s_[i];
  return rpm_to_rad_s(s.rpm_start + (s.rpm_end - s.rpm_start) * (tau / s.duration_s));
}

double SpeedProfile::angle_m(double t) const {
  if (t >= duration()) return start_angle_.back() + rpm_to_rad_s(segments_.back().rpm_end) * (t - duration());
  const std::size_t i = segment_at(t);
  const SpeedSegment& s = segments_[i];
  const double tau = t - start_s_[i];
  const double w0 = rpm_to_rad_s(s.rpm_start);
  const double accel = (rpm_to_rad_s(s.rpm_end) - w0) / s.duration_s;  // [rad/s^2]
  return start_angle_[i] + w0 * tau + 0.5 * accel * tau * tau;
}

namespace {
bool parse_number(std::string_view text, double& value) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc{} && end == text.data() + text.size() && std::isfinite(value);
}
}  // namespace

std::vector<SpeedSegment> parse_speed_profile(std::string_view text) {
  std::vector<SpeedSegment> segments;
  std::string_view rest = text;
  const auto bad = [&](std::string_view item, std::string_view why) {
    return InputError(Fault::kUsage,
                      fmt::format("'{}': segment '{}' {}; write rpm[-rpm_end]:seconds segments separated by commas, "
                                  "e.g. \"200:5,200-1000:3,1000:2\"",
                                  text, item, why),
                      Where::at_option("--profile"));
  };
  if (rest.empty()) throw bad("", "is empty");
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t colon = item.find(':');
    if (colon == std::string_view::npos) throw bad(item, "has no ':seconds'");
    const std::string_view speeds = item.substr(0, colon);
    // The range dash is the first '-' after the first character (which may be a sign).
    const std::size_t dash = speeds.size() > 1 ? speeds.find('-', 1) : std::string_view::npos;
    SpeedSegment s{};
    if (!parse_number(speeds.substr(0, dash), s.rpm_start)) throw bad(item, "has a bad start speed [r/min]");
    s.rpm_end = s.rpm_start;
    if (dash != std::string_view::npos && !parse_number(speeds.substr(dash + 1), s.rpm_end)) {
      throw bad(item, "has a bad end speed [r/min]");
    }
    if (!parse_number(item.substr(colon + 1), s.duration_s) || !(s.duration_s > 0.0)) {
      throw bad(item, "needs a duration > 0 [s] after ':'");
    }
    segments.push_back(s);
  }
  return segments;
}

}  // namespace resolver
