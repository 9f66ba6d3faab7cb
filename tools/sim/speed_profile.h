// The bench's speed profile: a sequence of constant-speed and linear-ramp
// segments, integrated analytically to the mechanical angle at any time.
// Pure maths (no I/O); parse_speed_profile() reads the CLI's text form.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/errors.h"

namespace resolver {

/// One segment: constant speed when rpm_start == rpm_end, linear ramp otherwise.
/// A "step" is two consecutive constant segments.
struct SpeedSegment {
  double duration_s;  ///< [s] > 0
  double rpm_start;   ///< [r/min] mechanical speed at the segment's start
  double rpm_end;     ///< [r/min] mechanical speed at the segment's end
};

class SpeedProfile {
 public:
  /// Throws std::invalid_argument naming the bad segment when a duration is not
  /// > 0 or a value is not finite, or when `segments` is empty.
  explicit SpeedProfile(std::vector<SpeedSegment> segments);

  /// [s] total duration.
  [[nodiscard]] double duration() const { return start_s_.back(); }
  /// [rad/s] mechanical speed at time t [s] from the start (the last speed holds after the end).
  [[nodiscard]] double omega_m(double t) const;
  /// [rad] mechanical angle travelled from time 0 to t [s] (continuous; exact for
  /// the piecewise-linear speed: a quadratic within each ramp).
  [[nodiscard]] double angle_m(double t) const;
  [[nodiscard]] const std::vector<SpeedSegment>& segments() const { return segments_; }

 private:
  [[nodiscard]] std::size_t segment_at(double t) const;

  std::vector<SpeedSegment> segments_;
  std::vector<double> start_s_;      // start time of each segment, plus the end time
  std::vector<double> start_angle_;  // [rad] angle at each segment's start
};

/// [rad/s] from [r/min].
[[nodiscard]] constexpr double rpm_to_rad_s(double rpm) { return rpm * (kTwoPi / 60.0); }

/// Parses "200:5,200-1000:3,1000:2": comma-separated rpm[-rpm_end]:seconds
/// segments (a leading '-' is a negative speed: "-200--100:1"). Returns the
/// segments, or throws InputError (Fault::kUsage, option --profile) naming the
/// bad segment and showing the form.
[[nodiscard]] std::vector<SpeedSegment> parse_speed_profile(std::string_view text);

}  // namespace resolver
