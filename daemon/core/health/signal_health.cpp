#include "daemon/core/health/signal_health.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace resolver {

namespace {

/// Histories shorter than this give no median worth testing against: the MAD of
/// fewer samples scatters too much (at 8 samples it fell below half of sigma and
/// flagged plain noise); half the window is reached after 32 ms at 2 kHz.
constexpr std::size_t kMinHistory = RunningMedian::kSize / 2;
/// A run of this many "outliers" in a row is a new level (an amplitude step, a
/// speed change), not impulses: the histories restart from it.
constexpr int kLevelChangeRun = 8;
/// Steps across more lost samples than this are not used for speed or prediction.
constexpr std::int64_t kMaxStepGap = 8;
/// Fewest angle steps in a block that decide stopped and overspeed (a tenth of a
/// block at 2 kHz; a median of fewer says little).
constexpr std::size_t kMinSpeedSteps = 20;
/// 1.4826 MAD = sigma for Gaussian data.
constexpr double kMadToSigma = 1.4826;

/// Share of a block's clean radii left out at each end of the DOS swing. The running
/// outlier test misses some spikes (a 15 % spike on sin near the radius' crest of a 15 %
/// offset sensor is within its 8 sigmas): 3000-count spikes at 50/s on such a sensor put
/// the plain range at 54-60 % of the mean in a fifth of the blocks, degradation for 13 % of
/// the log, where the sensor swings 35 %. Spikes at 50/s are 2.5 % of a 2 kHz block's
/// samples; a radius swinging as a sinusoid (imbalance, offsets) dwells at its extremes,
/// so its 5 % and 95 % points are within 1.2 % of its range of the extremes, and an open
/// channel still swings its whole amplitude.
constexpr double kSwingTrim = 0.05;

/// The [low, high] radius of the DOS swing: the kSwingTrim and 1 - kSwingTrim points of
/// `r` (reordered); the plain range of fewer than 1 / kSwingTrim values.
std::pair<double, double> swing_range(std::vector<double>& r) {
  if (r.empty()) return {0.0, 0.0};
  const auto k = static_cast<std::ptrdiff_t>(kSwingTrim * static_cast<double>(r.size()));
  const auto lo = r.begin() + k, hi = r.end() - 1 - k;
  std::nth_element(r.begin(), lo, r.end());
  const double low = *lo;
  std::nth_element(lo, hi, r.end());
  return {low, *hi};
}

double median_of(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::string_view fault_name(SignalFault fault) {
  switch (fault) {
    case SignalFault::kLossOfSignal: return "loss_of_signal";
    case SignalFault::kDegradationOfSignal: return "degradation_of_signal";
    case SignalFault::kLossOfTracking: return "loss_of_tracking";
    case SignalFault::kClipping: return "clipping";
    case SignalFault::kStopped: return "stopped";
    case SignalFault::kOverspeed: return "overspeed";
    case SignalFault::kOutliers: return "outliers";
  }
  return "unknown";
}

std::vector<std::string> lasting_faults(const FaultCounts& counts, std::int64_t total, double share) {
  std::vector<std::string> out;
  if (total <= 0) return out;
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) {
    const auto f = static_cast<SignalFault>(i);
    if (f == SignalFault::kStopped || counts[i] == 0) continue;
    const double part = static_cast<double>(counts[i]) / static_cast<double>(total);
    if (part < share) continue;
    out.push_back(fmt::format("{} for {} of {} samples ({:.0f} %)", fault_name(f), counts[i], total, 100.0 * part));
  }
  return out;
}

void AmplitudeStats::add(double r) {
  if (n == 0 || r < min) min = r;
  if (n == 0 || r > max) max = r;
  sum += r;
  ++n;
}

void RunningMedian::add(double v) {
  ring_[next_] = v;
  next_ = (next_ + 1) % kSize;
  count_ = std::min(count_ + 1, kSize);
  if (median_age_ != kNever) ++median_age_;
  if (sigma_age_ != kNever) ++sigma_age_;
}

double RunningMedian::median() {
  if (stale(median_age_)) {
    std::copy_n(ring_.begin(), count_, scratch_.begin());
    const auto mid = scratch_.begin() + static_cast<std::ptrdiff_t>(count_ / 2);
    std::nth_element(scratch_.begin(), mid, scratch_.begin() + static_cast<std::ptrdiff_t>(count_));
    median_ = *mid;
    median_age_ = 0;
  }
  return median_;
}

double RunningMedian::robust_sigma() {
  if (stale(sigma_age_)) {
    const double med = median();
    for (std::size_t i = 0; i < count_; ++i) scratch_[i] = std::abs(ring_[i] - med);
    const auto mid = scratch_.begin() + static_cast<std::ptrdiff_t>(count_ / 2);
    std::nth_element(scratch_.begin(), mid, scratch_.begin() + static_cast<std::ptrdiff_t>(count_));
    sigma_ = kMadToSigma * *mid;
    sigma_age_ = 0;
  }
  return sigma_;
}

SignalHealthMonitor::SignalHealthMonitor(const SignalHealthConfig& config, int p_r, double sample_rate_hz)
    : config_(config), p_r_(p_r), sample_rate_hz_(sample_rate_hz) {}

namespace {
/// sqrt(s^2 + c^2): signal values are far from overflow, so std::hypot's care is not needed (and costs).
double radius(const Sample& s) { return std::sqrt(s.sin * s.sin + s.cos * s.cos); }
}  // namespace

double SignalHealthMonitor::level_reference() const {
  return config_.full_scale > 0.0 ? config_.full_scale : peak_block_amplitude_;
}

bool SignalHealthMonitor::sincos_lost(const Sample& s) const {
  return s.has_sincos && radius(s) < config_.loss_of_signal_fraction * level_reference();
}

AmplitudeStats SignalHealthMonitor::take_amplitude_window() {
  AmplitudeStats out = amplitude_window_;
  amplitude_window_ = AmplitudeStats{};
  return out;
}

std::vector<SignalFaultEvent> SignalHealthMonitor::take_events() {
  std::vector<SignalFaultEvent> out;
  out.swap(events_);
  return out;
}

bool SignalHealthMonitor::is_outlier(const Sample& s, double r, double angle) {
  // One ADC count (twice the clip margin of half a count) is the finest the
  // radius can be known; the MAD of quantized, noise-free data can be smaller.
  const double quantum = std::max(2.0 * config_.clip_margin, 1e-12);
  bool outlier = false;
  // The radius: beyond its running level's spread AND off the line through the last two
  // good samples. The level alone is not enough: a real sensor's radius swings with
  // 2 theta by its gain error (alpha / 2 of the amplitude), and where the rotor lingers
  // (a reversal, a creep) the last 128 samples span a sliver of that swing, so the
  // level's spread collapses and the swing's slow return read as impulsive (every
  // reversal of a 5 % or 13 % imbalance raised 7 outliers, and resolverd's windows
  // around it were called faulty). On the line, what is left is the swing's curvature
  // (alpha r (2 step)^2: a few counts where the rotor lingers) and the noise. The line
  // alone is not enough either: a spike it misses at speed (the curvature is hundreds
  // of counts there) would bend the next predictions; the level keeps those normal.
  const std::int64_t gap = s.index - good_index_;
  if (have_good_angle_ && (gap < 1 || gap > kMaxStepGap)) have_good_angle_ = false;
  if (radius_.size() >= kMinHistory) {
    const double sigma = std::max(radius_.robust_sigma(), quantum);
    outlier = std::abs(r - radius_.median()) > config_.outlier_sigmas * sigma;
  }
  double off_line = 0.0;
  const bool have_off_line = have_good_angle_ && have_radius_slope_;
  if (have_off_line) {
    off_line = r - (good_radius_ + radius_slope_ * static_cast<double>(gap));
    // Asked only of a sample the level calls impulsive: the history's median and spread
    // are re-sorted when asked, and every sample passes here.
    if (outlier && off_line_.size() >= kMinHistory) {
      const double sigma = std::max(off_line_.robust_sigma(), quantum);
      outlier = std::abs(off_line - off_line_.median()) > config_.outlier_sigmas * sigma;
    }
  }
  // The angle: predicted from the last good sample and the median step; the
  // residual is tested against its own running median, so a steady lag under
  // acceleration is not an outlier, only a jump against the neighbours is.
  double residual = 0.0;
  bool have_residual = false;
  if (have_good_angle_ && step_.size() >= kMinHistory) {
    const double step = step_.median();
    if (std::abs(step) < config_.overspeed_rad_per_sample) {  // near pi per sample the prediction aliases
      residual = wrap_pi(angle - (good_angle_ + step * static_cast<double>(gap)));
      have_residual = true;
      if (angle_residual_.size() >= kMinHistory) {
        const double sigma = std::max(angle_residual_.robust_sigma(), quantum / r);
        outlier = outlier || std::abs(residual - angle_residual_.median()) > config_.outlier_sigmas * sigma;
      }
    }
  }
  if (outlier && ++outlier_run_ < kLevelChangeRun) return true;
  if (outlier) {
    // A new level: restart the histories from this sample (the run so far stays counted).
    radius_.clear();
    off_line_.clear();
    step_.clear();
    angle_residual_.clear();
    have_residual = false;
    have_good_angle_ = false;
  }
  outlier_run_ = 0;
  radius_.add(r);
  if (have_off_line) off_line_.add(off_line);
  if (have_good_angle_) step_.add(wrap_pi(angle - good_angle_) / static_cast<double>(gap));
  if (have_residual) angle_residual_.add(residual);
  have_radius_slope_ = have_good_angle_;
  if (have_radius_slope_) radius_slope_ = (r - good_radius_) / static_cast<double>(gap);
  have_good_angle_ = true;
  good_angle_ = angle;
  good_radius_ = r;
  good_index_ = s.index;
  return false;
}

void SignalHealthMonitor::add_speed(const Sample& s, bool sincos_usable, double sincos_angle) {
  // Speed: the reference when there is one (mechanical, so it resolves p_r times
  // more speed before it aliases), else the R/D angle, else the sin/cos angle.
  double angle = 0.0;
  int source = 0;  // 0 none, 1 reference, 2 R/D or sin/cos
  if (s.has_ref) {
    angle = s.theta_m_ref;
    source = 1;
  } else if (s.has_rd) {
    angle = s.theta_rd;
    source = 2;
  } else if (sincos_usable) {
    angle = sincos_angle;
    source = 2;
  }
  if (source == 0) {
    have_angle_ = false;
    return;
  }
  const bool same_source = have_angle_ && angle_source_ == source;
  const std::int64_t gap = s.index - last_angle_index_;
  if (same_source && gap >= 1 && gap <= kMaxStepGap) {
    double step = wrap_pi(angle - last_angle_);
    if (source == 1) step *= static_cast<double>(p_r_);  // mechanical -> resolver electrical
    block_.travel += step;
    // The counter is the clock between two samples: gap / rate, not the difference of
    // their t, which jumps where the sample clock re-anchors after a stall.
    block_.travel_time += sample_rate_hz_ > 0.0 ? static_cast<double>(gap) / sample_rate_hz_ : s.t - last_angle_t_;
    block_.steps.push_back(std::abs(step) / static_cast<double>(gap));
    block_.steps_from_reference = source == 1;
  }
  have_angle_ = true;
  angle_source_ = source;
  last_angle_ = angle;
  last_angle_t_ = s.t;
  last_angle_index_ = s.index;
}

void SignalHealthMonitor::add(const Sample& s) {
  // Blocks on a grid anchored at the first sample, so they do not drift by a
  // sample per block; time going back (a new pass, a re-anchored clock) or an
  // unusable t re-anchors it.
  if (!have_grid_ || !(s.t >= block_.t_last) || !std::isfinite(s.t)) {
    if (block_.n > 0) evaluate_block();
    have_grid_ = std::isfinite(s.t);
    grid_t0_ = s.t;
    block_number_ = 0;
  } else {
    // The 1e-6 of a block absorbs rounding in t = index / rate (0.1 s is not exact in binary).
    const auto number = static_cast<std::int64_t>(std::floor((s.t - grid_t0_) / config_.block_s + 1e-6));
    if (number != block_number_) {
      if (block_.n > 0) evaluate_block();
      block_number_ = number;
    }
  }
  if (block_.n == 0) {
    block_.t_first = s.t;
    block_.index_first = s.index;
  }
  ++block_.n;
  block_.t_last = s.t;
  ++samples_;

  bool sincos_usable = false;
  double sincos_angle = 0.0;
  last_clipped_ = false;
  last_outlier_ = false;
  if (s.has_sincos) {
    const double r = radius(s);
    amplitude_window_.add(r);
    amplitude_total_.add(r);
    block_.r_all.add(r);
    const double clip_at = config_.full_scale - config_.clip_margin;
    if (config_.full_scale > 0.0 && (std::abs(s.sin) >= clip_at || std::abs(s.cos) >= clip_at)) {
      last_clipped_ = true;
      if (block_.clipped++ == 0) {
        block_.clipped_t = s.t;
        block_.clipped_index = s.index;
      }
    }
    sincos_usable = r >= config_.loss_of_signal_fraction * level_reference();  // as sincos_lost()
    if (sincos_usable) {
      sincos_angle = std::atan2(s.sin, s.cos);
      if (is_outlier(s, r, sincos_angle)) {
        last_outlier_ = true;
        if (block_.outliers++ == 0) {
          block_.outlier_t = s.t;
          block_.outlier_index = s.index;
        }
        sincos_usable = false;  // an impulse is not an angle for speed or tracking
      } else {
        block_.r_clean.add(r);
        block_.r_clean_values.push_back(r);
      }
    }
    if (sincos_usable && s.has_rd) {
      const double d = std::abs(wrap_pi(s.theta_rd - sincos_angle));
      ++block_.lot_checked;
      if (d > config_.loss_of_tracking_rad) ++block_.lot_beyond;
      block_.lot_worst = std::max(block_.lot_worst, d);
    }
  }
  add_speed(s, sincos_usable, sincos_angle);
}

std::uint8_t SignalHealthMonitor::last_sample_faults() const {
  std::uint8_t mask = 0;
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) {
    const auto f = static_cast<SignalFault>(i);
    bool on = faults_[i].active;
    if (f == SignalFault::kClipping) on = last_clipped_;
    if (f == SignalFault::kOutliers) on = last_outlier_;
    if (on) mask = static_cast<std::uint8_t>(mask | (1U << i));
  }
  return mask;
}

void SignalHealthMonitor::finish() {
  if (block_.n > 0) evaluate_block();
}

void SignalHealthMonitor::new_pass() {
  // The angle test predicts from the pass's own first samples: the joint is a jump
  // in angle and in speed (a log ending at 1000 r/min starts again at 200).
  have_good_angle_ = false;
  step_.clear();
  off_line_.clear();
  have_radius_slope_ = false;
  angle_residual_.clear();
  outlier_run_ = 0;
  have_angle_ = false;  // no speed step across the joint
}

void SignalHealthMonitor::set_fault(SignalFault f, bool present, std::int64_t samples, double t, std::int64_t index,
                                    const std::string& detail) {
  SignalFaultState& st = faults_[static_cast<std::size_t>(f)];
  if (present) {
    st.samples += samples;
    st.last_t = block_.t_last;
    if (!st.active) {
      st.active = true;
      ++st.episodes;
      if (std::isnan(st.first_t)) st.first_t = t;
      events_.push_back({f, true, t, index, detail});
    }
  } else if (st.active) {
    st.active = false;
    events_.push_back({f, false, t, index, {}});
  }
}

void SignalHealthMonitor::evaluate_block() {
  Block& b = block_;
  // Full scale unknown (a CSV export in volts): the levels are judged against the
  // largest block amplitude seen so far, and the absolute ones (too low, no
  // headroom, clipping) cannot be judged at all.
  const bool fs_known = config_.full_scale > 0.0;
  const double fs = level_reference();
  const double t0 = b.t_first;
  const std::int64_t i0 = b.index_first;

  // LOS, DOS and LOT are known only from blocks with sin/cos; without them they keep their state.
  bool lost = fault(SignalFault::kLossOfSignal).active;
  if (b.r_all.n > 0 && fs > 0.0) {
    const double level = config_.loss_of_signal_fraction * fs;
    lost = b.r_all.mean() < level;
    set_fault(SignalFault::kLossOfSignal, lost, b.n, t0, i0,
              fs_known ? fmt::format("sin/cos amplitude {:.1f} (mean over the block), below {:.0f} = {:g} % of full "
                                     "scale {:.0f}: no excitation, or both channels open",
                                     b.r_all.mean(), level, 100.0 * config_.loss_of_signal_fraction, fs)
                       : fmt::format("sin/cos amplitude {:.4g} (mean over the block), below {:.4g} = {:g} % of the "
                                     "largest block amplitude so far ({:.4g}; full scale unknown): no excitation, "
                                     "or both channels open",
                                     b.r_all.mean(), level, 100.0 * config_.loss_of_signal_fraction, fs));
  }
  if (b.r_clean.n > 0 && !lost) {
    const double mean = b.r_clean.mean();
    const auto [low, high] = swing_range(block_.r_clean_values);
    const double swing = (high - low) / mean;
    std::string why;
    if (fs_known && mean < config_.degradation_low_fraction * fs) {
      why = fmt::format("sin/cos amplitude {:.0f}, below {:g} % of full scale {:.0f}", mean,
                        100.0 * config_.degradation_low_fraction, fs);
    } else if (fs_known && mean > config_.degradation_high_fraction * fs) {
      why = fmt::format("sin/cos amplitude {:.0f}, above {:g} % of full scale {:.0f} (no headroom)", mean,
                        100.0 * config_.degradation_high_fraction, fs);
    } else if (swing > config_.degradation_mismatch) {
      why = fmt::format("sin/cos amplitude swings {:.0f} .. {:.0f} over the block (5-95 % of its samples without "
                        "outliers; {:.1f} % of its mean, limit {:g} %): the channels are imbalanced, or one is weak or open",
                        low, high, 100.0 * swing, 100.0 * config_.degradation_mismatch);
    }
    set_fault(SignalFault::kDegradationOfSignal, !why.empty(), b.n, t0, i0, why);
    peak_block_amplitude_ = std::max(peak_block_amplitude_, mean);
  } else if (lost) {
    set_fault(SignalFault::kDegradationOfSignal, false, 0, t0, i0, {});  // LOS says more
  }
  if (b.lot_checked > 0) {
    const bool lot = 2 * b.lot_beyond > b.lot_checked;
    set_fault(SignalFault::kLossOfTracking, lot, b.n, t0, i0,
              fmt::format("R/D angle and atan2(sin, cos) differ by more than {:.1f} deg in {} of {} samples (worst "
                          "{:.1f} deg): the converter does not follow the signals",
                          rad_to_deg(config_.loss_of_tracking_rad), b.lot_beyond, b.lot_checked,
                          rad_to_deg(b.lot_worst)));
  } else if (lost) {
    set_fault(SignalFault::kLossOfTracking, false, 0, t0, i0, {});  // nothing to track: LOS says it
  }
  if (b.r_all.n > 0) {
    // Started at the first offending sample; ended at the first block without one
    // (its first_t and index are 0 there: the block's start says when).
    set_fault(SignalFault::kClipping, b.clipped > 0, b.clipped, b.clipped > 0 ? b.clipped_t : t0,
              b.clipped > 0 ? b.clipped_index : i0,
              fmt::format("{} sample(s) with |sin| or |cos| at full scale {:.0f}: the ADC clips", b.clipped, fs));
    set_fault(SignalFault::kOutliers, b.outliers > 0, b.outliers, b.outliers > 0 ? b.outlier_t : t0,
              b.outliers > 0 ? b.outlier_index : i0,
              fmt::format("{} impulsive sample(s): radius or angle beyond {:g} robust sigmas of the running median",
                          b.outliers, config_.outlier_sigmas));
  }

  // Speed needs a few steps: a block that kept only a handful (samples lost, the speed
  // source missing) says nothing about stop or overspeed and leaves both as they were.
  const bool speed_known = b.steps.size() >= kMinSpeedSteps;
  if (speed_known) {
    const double step = median_of(b.steps);
    const double over = config_.overspeed_rad_per_sample;
    std::string speed;
    if (sample_rate_hz_ > 0.0 && p_r_ > 0) {
      const double per_rad = sample_rate_hz_ * 60.0 / (kTwoPi * static_cast<double>(p_r_));  // r/min per rad/sample
      speed = fmt::format(" ({:.0f} r/min at {:g} Hz, p_r = {}; the line is {:.0f} r/min, aliasing starts at {:.0f} r/min)",
                          step * per_rad, sample_rate_hz_, p_r_, over * per_rad, kPi * per_rad);
    }
    set_fault(SignalFault::kOverspeed, step > over, b.n, t0, i0,
              fmt::format("resolver electrical travel {:.3f} rad per sample{}, beyond {:.3f}{}{}", step,
                          b.steps_from_reference ? " (from the reference angle)" : "", over, speed,
                          b.steps_from_reference ? ""
                                                 : "; without a reference angle a speed near the sample rate aliases "
                                                   "and may read slow"));
  }
  if (speed_known && b.travel_time > 0.0) {
    const double hz = std::abs(b.travel) / b.travel_time / kTwoPi;
    set_fault(SignalFault::kStopped, hz < config_.stopped_below_hz, b.n, t0, i0,
              fmt::format("resolver electrical speed {:.3g} Hz, below {:g} Hz: the motor stands still (nothing for "
                          "the estimators to learn from)",
                          hz, config_.stopped_below_hz));
  }
  std::vector<double> steps = std::move(block_.steps);  // keeps its capacity: no allocation per block
  std::vector<double> radii = std::move(block_.r_clean_values);
  steps.clear();
  radii.clear();
  block_ = Block{};
  block_.steps = std::move(steps);
  block_.r_clean_values = std::move(radii);
}

SignalHealthSummary summarize(const SignalHealthMonitor& monitor, std::vector<SignalFaultEvent> events, double t_first,
                              double t_last) {
  SignalHealthSummary out;
  out.samples = monitor.samples();
  out.t_first = t_first;
  out.t_last = t_last;
  out.amplitude = monitor.amplitude_total();
  out.events = std::move(events);
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) {
    const SignalFaultState& st = monitor.faults()[i];
    SignalHealthSummary::Fault& f = out.faults[i];
    f.fault = static_cast<SignalFault>(i);
    f.samples = st.samples;
    f.episodes = st.episodes;
    f.share = out.samples > 0 ? static_cast<double>(st.samples) / static_cast<double>(out.samples) : 0.0;
    f.first_t = st.first_t;
    f.last_t = st.last_t;
    f.active_at_end = st.active;
  }
  return out;
}

SignalHealthSummary summarize_signal_health(const std::vector<Sample>& samples, const SignalHealthConfig& config,
                                            int p_r, double sample_rate_hz) {
  SignalHealthMonitor monitor(config, p_r, sample_rate_hz);
  std::vector<SignalFaultEvent> events;
  for (const Sample& s : samples) monitor.add(s);
  monitor.finish();
  return summarize(monitor, monitor.take_events(), samples.empty() ? 0.0 : samples.front().t,
                   samples.empty() ? 0.0 : samples.back().t);
}

std::vector<SignalFault> SignalHealthSummary::holding(double min_share) const {
  std::vector<SignalFault> out;
  for (const Fault& f : faults) {
    if (f.samples > 0 && f.share >= min_share) out.push_back(f.fault);
  }
  return out;
}

std::string SignalHealthSummary::describe() const {
  std::string out;
  for (const Fault& f : faults) {
    if (f.samples == 0) continue;
    out += fmt::format("{}{} {:.1f} % of the log ({} sample(s), {} episode(s), {:.3f} .. {:.3f} s into it{})",
                       out.empty() ? "" : "; ", fault_name(f.fault), 100.0 * f.share, f.samples, f.episodes,
                       f.first_t - t_first, f.last_t - t_first, f.active_at_end ? ", still at the end" : "");
  }
  return out.empty() ? std::string("no signal fault") : out;
}

}  // namespace resolver
