// Signal health of the resolver chain, reported the way a resolver-to-digital
// converter reports it on its fault pins (the AD2S1210's LOS, DOS and LOT are
// the model), plus what a sampled bench adds: clipping, stop, overspeed and
// impulsive samples. Pure: no I/O, no clocks; time is the samples' own t.
//
//   fault                  condition (thresholds: SignalHealthConfig)
//   loss_of_signal         mean sin/cos amplitude r = sqrt(s^2 + c^2) of a block below the LOS level
//                          (dead excitation, both channels open)
//   degradation_of_signal  amplitude outside its band, or r swinging over the block by more than
//                          the mismatch share of its mean (one channel weak or open: imbalance)
//   loss_of_tracking       R/D angle and atan2(sin, cos) disagree beyond the LOT angle in more
//                          than half of the block's samples
//   clipping               a sin or cos sample at the ADC's full scale
//   stopped                electrical speed over the block below the stop line
//   overspeed              electrical travel per sample beyond the overspeed line (pi per sample
//                          aliases; the line sits well before that)
//   outliers               a sample whose radius (against its running level and off the line
//                          of its last two good samples) or angle is impulsive against a
//                          running median/MAD (robust z-score)
//
// Samples are evaluated in blocks of `block_s` of sample time. A fault starts at
// the first block (or, for the per-sample faults clipping and outliers, the first
// sample) that shows it and ends at the first block that does not; each start and
// end is an event the caller logs once. Counts are samples: the samples a fault held
// for (block faults count the block's samples).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/sample.h"

namespace resolver {

enum class SignalFault : std::uint8_t {
  kLossOfSignal,
  kDegradationOfSignal,
  kLossOfTracking,
  kClipping,
  kStopped,
  kOverspeed,
  kOutliers,
};
inline constexpr std::size_t kSignalFaultCount = 7;

/// Stable names (health_t fault_name, run report, JSON): "loss_of_signal", ...
[[nodiscard]] std::string_view fault_name(SignalFault fault);

/// Share of a fit's samples a signal fault must hold for before the fit cannot be
/// "explained" (resolver-model explain, resolverd's live model fit): a tenth, so one
/// fault block of 0.1 s (block_s) in a few seconds of bench is a note, and a dead,
/// clipped or aliased tenth is not.
inline constexpr double kUntrustedFaultShare = 0.1;

/// Samples each fault held for, over some span of samples.
using FaultCounts = std::array<std::int64_t, kSignalFaultCount>;

/// The faults that held for at least `share` of `total` samples, worded for a note and
/// a verdict ("loss_of_signal for 9000 of 10000 samples (90 %)"). stopped is never among
/// them (a standstill is motion). Outliers count sample by sample: a few impulses are
/// discovery's own (kept out of the fit), but a tenth of the samples impulsive is garbage
/// that sets the floor itself (every other sample's sin/cos garbage once read
/// "explained" at 0.82x a floor estimated from the garbage: issue 25).
[[nodiscard]] std::vector<std::string> lasting_faults(const FaultCounts& counts, std::int64_t total, double share);

/// Thresholds. Defaults come from the physics of a 16-bit ADC bench; each says where from.
struct SignalHealthConfig {
  /// [signal units, counts on the default layout] the largest |sin| or |cos| the ADC can
  /// report; the caller takes it from the DBC signal's range (daemon/app). 0 = unknown
  /// (a CSV export in volts): loss of signal is then judged against the largest block
  /// amplitude seen so far, and low level, headroom and clipping are not judged.
  double full_scale = 32767.0;
  /// [signal units] a sample within this of +-full_scale is clipped: half an ADC count.
  double clip_margin = 0.5;
  /// LOS below this share of full scale. At 5 % of a 16-bit full scale (1638 counts) the
  /// ADC's own quantization (1/sqrt(12) count rms per channel) alone is 0.18 mrad rms of
  /// angle, two LSB of a 16-bit R/D converter: the signal cannot carry the bench's
  /// resolution any more. A dead excitation leaves ADC noise and offsets, far below.
  double loss_of_signal_fraction = 0.05;
  /// DOS below this share of full scale: two bits of the ADC range unused (quantization
  /// noise on the angle 4x what the range allows).
  double degradation_low_fraction = 0.25;
  /// DOS above this share: under 5 % headroom, offsets and noise push the peaks into clipping.
  double degradation_high_fraction = 0.95;
  /// DOS when (r_max - r_min) / r_mean over a block exceeds this. Amplitude imbalance alpha
  /// swings r by alpha (Hanselman eq. 4), offsets o by about 2 o, a harmonic K by 2 K.
  /// Real sensors' gain errors reach 13-15 % with offsets and harmonics of a few percent
  /// on top, and the fit models them exactly at those sizes (envelope_spectrum.h): they
  /// are effects to fit, not faults (15 % offsets swing r by 35 %). A channel at half the
  /// other's gain, or an open one (its whole amplitude), is.
  double degradation_mismatch = 0.5;
  /// [rad] LOT beyond 5 degrees of R/D vs sin/cos disagreement: the AD2S1205's own LOT
  /// limit on its tracking error; the catalog's errors are well below 1 degree.
  double loss_of_tracking_rad = 5.0 * kPi / 180.0;
  /// [rad per sample] overspeed beyond pi/4 of resolver electrical travel per sample: the
  /// 4th harmonic of theta (the highest the catalog puts into the angle error, K_5 in
  /// Hanselman eq. 9) reaches the Nyquist limit there; pi per sample aliases theta itself.
  double overspeed_rad_per_sample = kPi / 4.0;
  /// [Hz] stopped below 0.1 resolver electrical revolutions per second: the Hwang
  /// integral's line between a slow revolution and a stop (HwangIntegralConfig
  /// max_revolution_time_s = 10 s).
  double stopped_below_hz = 0.1;
  /// Outlier beyond this many robust standard deviations (1.4826 MAD of the last 128
  /// samples) from the running median. Gaussian noise never gets there (8 sigma: 1e-15),
  /// even when the 128-sample MAD underestimates sigma by its typical 10-20 %.
  double outlier_sigmas = 8.0;
  /// [s] evaluation block: a tenth of a second holds a resolver electrical revolution at
  /// 200 r/min with p_r = 3 and reports a fault within 0.1 s of sample time.
  double block_s = 0.1;
};

/// A fault starting or ending, to be logged once.
struct SignalFaultEvent {
  SignalFault fault = SignalFault::kLossOfSignal;
  bool started = true;        ///< false: the fault ended
  double t = 0.0;             ///< [s] sample time of the first sample that showed (or cleared) it
  std::int64_t index = 0;     ///< that sample's index
  std::string detail;         ///< what was measured against which threshold (started only)
};

/// What one fault has done so far.
struct SignalFaultState {
  bool active = false;
  std::int64_t samples = 0;   ///< samples it held for (per-sample faults: the offending samples)
  std::int64_t episodes = 0;  ///< times it started
  double first_t = std::numeric_limits<double>::quiet_NaN();  ///< [s] first start
  double last_t = std::numeric_limits<double>::quiet_NaN();   ///< [s] last sample it held for
};

/// Amplitude r = sqrt(s^2 + c^2) statistics [signal units] over some span of samples.
struct AmplitudeStats {
  std::int64_t n = 0;
  double sum = 0.0;
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
  void add(double r);
  [[nodiscard]] double mean() const {
    return n > 0 ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
  }
};

/// Median and median absolute deviation of the last kSize values. Each is
/// recomputed (a selection over the ring) only when asked for and at most once
/// per kRefreshEvery additions once the ring is full, so it lags the newest
/// values by up to that many: a few comparisons per sample, not a sort.
class RunningMedian {
 public:
  static constexpr std::size_t kSize = 128;
  static constexpr std::size_t kRefreshEvery = 32;
  void add(double v);
  void clear() {
    count_ = next_ = 0;
    median_age_ = sigma_age_ = kNever;
  }
  [[nodiscard]] std::size_t size() const { return count_; }
  /// Needs size() > 0.
  [[nodiscard]] double median();
  /// 1.4826 MAD: the standard deviation of Gaussian data, robust to a few outliers.
  [[nodiscard]] double robust_sigma();

 private:
  static constexpr std::size_t kNever = ~std::size_t{0};
  [[nodiscard]] bool stale(std::size_t age) const {
    return age == kNever || (age > 0 && (count_ < kSize || age >= kRefreshEvery));
  }
  std::array<double, kSize> ring_{};
  std::array<double, kSize> scratch_{};
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  std::size_t median_age_ = kNever;  ///< additions since median_ was computed
  std::size_t sigma_age_ = kNever;
  double median_ = 0.0;
  double sigma_ = 0.0;
};

class SignalHealthMonitor {
 public:
  /// `p_r` resolver pole pairs (a reference angle becomes electrical with it),
  /// `sample_rate_hz` (0 = unknown) only words the overspeed message in r/min.
  SignalHealthMonitor(const SignalHealthConfig& config, int p_r, double sample_rate_hz);

  void set_pole_pairs(int p_r) { p_r_ = p_r; }
  /// The input's full scale (0 = unknown) and clip margin, once the input is known.
  void set_full_scale(double full_scale, double clip_margin) {
    config_.full_scale = full_scale;
    config_.clip_margin = clip_margin;
  }
  void set_sample_rate(double hz) { sample_rate_hz_ = hz; }
  /// New thresholds (a config reload) from the next sample on; counts, episodes and
  /// the open block stay.
  void set_config(const SignalHealthConfig& config) {
    if (config.block_s != config_.block_s) have_grid_ = false;  // a new grid from the next sample
    config_ = config;
  }

  /// One sample. Cannot fail; samples without sin/cos or angles only move what they can.
  void add(const Sample& s);
  /// End of input: evaluates the open block. Active faults stay active (the log ended in them).
  void finish();
  /// The next sample starts a new pass of a looped log: it does not follow the
  /// last one (the angle jumps where the log's end meets its start), so the speed
  /// and the outlier test start over from it instead of reading the joint as an
  /// impulse or a step. Counts, faults and the open block stay.
  void new_pass();
  /// Starts and ends since the last call, oldest first.
  [[nodiscard]] std::vector<SignalFaultEvent> take_events();

  /// True when this sample's sin/cos amplitude is too small for an angle (below the LOS
  /// level): atan2 of it is noise and must be published as NaN, not as an angle.
  [[nodiscard]] bool sincos_lost(const Sample& s) const;
  /// The amplitude loss of signal is measured against: full scale, or without one the
  /// largest clean block amplitude so far (0 before the first block: nothing is lost).
  [[nodiscard]] double level_reference() const;

  [[nodiscard]] const std::array<SignalFaultState, kSignalFaultCount>& faults() const { return faults_; }
  [[nodiscard]] const SignalFaultState& fault(SignalFault f) const { return faults_[static_cast<std::size_t>(f)]; }
  /// The faults the last sample added is under (bit i: SignalFault i): the block faults
  /// that are active, and of the per-sample ones (clipping, outliers) only the sample's
  /// own, as their counts are (an outlier episode lasts from its first impulse to a block
  /// without one: a live window under one counted every sample as faulty, "outliers for
  /// 1065 of 1065 samples" at 2.5 % impulses, and refused to name a missing effect).
  [[nodiscard]] std::uint8_t last_sample_faults() const;
  /// Amplitude since the last take_amplitude_window() (health_t: the last second).
  [[nodiscard]] AmplitudeStats take_amplitude_window();
  /// Amplitude over everything seen.
  [[nodiscard]] const AmplitudeStats& amplitude_total() const { return amplitude_total_; }
  [[nodiscard]] std::int64_t samples() const { return samples_; }
  [[nodiscard]] const SignalHealthConfig& config() const { return config_; }

 private:
  struct Block {
    std::int64_t n = 0;
    double t_first = 0.0, t_last = 0.0;   ///< [s]
    std::int64_t index_first = 0;
    AmplitudeStats r_all;        ///< every sin/cos sample
    AmplitudeStats r_clean;      ///< without outliers (the DOS swing must not be a spike)
    std::vector<double> r_clean_values;  ///< their radii, for the swing's trimmed range
    std::int64_t lot_checked = 0, lot_beyond = 0;
    double lot_worst = 0.0;      ///< [rad]
    double travel = 0.0;         ///< [rad] electrical, summed wrapped steps
    double travel_time = 0.0;    ///< [s] the time those steps span
    std::vector<double> steps;   ///< |electrical step| [rad per sample]
    bool steps_from_reference = false;
    std::int64_t clipped = 0, outliers = 0;
    double clipped_t = 0.0, outlier_t = 0.0;  ///< [s] the first of each
    std::int64_t clipped_index = 0, outlier_index = 0;
  };

  void evaluate_block();
  void set_fault(SignalFault f, bool present, std::int64_t samples, double t, std::int64_t index,
                 const std::string& detail);
  /// Tests a sample with usable sin/cos (radius r, angle atan2(sin, cos) [rad]) and
  /// learns from it when it is not an outlier.
  bool is_outlier(const Sample& s, double r, double angle);
  void add_speed(const Sample& s, bool sincos_usable, double sincos_angle);

  SignalHealthConfig config_;
  int p_r_;
  double sample_rate_hz_;
  std::array<SignalFaultState, kSignalFaultCount> faults_{};
  std::vector<SignalFaultEvent> events_;
  AmplitudeStats amplitude_window_;
  AmplitudeStats amplitude_total_;
  double peak_block_amplitude_ = 0.0;  ///< largest clean block mean so far (the reference without a full scale)
  std::int64_t samples_ = 0;
  bool last_clipped_ = false, last_outlier_ = false;  ///< the last sample's own (last_sample_faults)
  Block block_;
  bool have_grid_ = false;
  double grid_t0_ = 0.0;           ///< [s] blocks cover [grid_t0 + k block_s, grid_t0 + (k+1) block_s)
  std::int64_t block_number_ = 0;
  // Outlier tests: the radius against its running median and, too, off the line
  // through the last two good samples; the sin/cos angle against the last good angle advanced
  // by the running median step.
  RunningMedian radius_;
  RunningMedian off_line_;  ///< the radius's residuals off that line
  RunningMedian step_;
  RunningMedian angle_residual_;
  int outlier_run_ = 0;
  bool have_good_angle_ = false;
  double good_angle_ = 0.0;
  double good_radius_ = 0.0;  ///< the last good sample's sin/cos radius
  double radius_slope_ = 0.0;  ///< [counts/sample] from the good sample before it
  bool have_radius_slope_ = false;
  std::int64_t good_index_ = 0;
  // The angle speed is measured on (see add_speed).
  bool have_angle_ = false;
  int angle_source_ = 0;
  double last_angle_ = 0.0;
  double last_angle_t_ = 0.0;
  std::int64_t last_angle_index_ = 0;
};

/// A whole log's signal health, for resolver-model and the verdict of a fit.
struct SignalHealthSummary {
  struct Fault {
    SignalFault fault = SignalFault::kLossOfSignal;
    std::int64_t samples = 0;   ///< samples it held for
    std::int64_t episodes = 0;  ///< times it started
    double share = 0.0;         ///< samples / all samples: the share of the log it held
    double first_t = std::numeric_limits<double>::quiet_NaN();  ///< [s] first start
    double last_t = std::numeric_limits<double>::quiet_NaN();   ///< [s] last block it held in
    bool active_at_end = false;
  };
  std::int64_t samples = 0;
  double t_first = 0.0, t_last = 0.0;  ///< [s] first and last sample
  AmplitudeStats amplitude;            ///< sin/cos amplitude over the log
  std::array<Fault, kSignalFaultCount> faults{};
  std::vector<SignalFaultEvent> events;  ///< every start and end, in order

  [[nodiscard]] const Fault& fault(SignalFault f) const { return faults[static_cast<std::size_t>(f)]; }
  /// The faults that held for at least `min_share` of the log (0.2 = a fifth).
  [[nodiscard]] std::vector<SignalFault> holding(double min_share) const;
  /// One line: "loss_of_signal 100.0 % of the log (20000 sample(s), 1 episode(s), 0.000 .. 9.999 s into it)"
  /// for each fault seen, or "no signal fault".
  [[nodiscard]] std::string describe() const;
};

/// Runs a fresh monitor over `samples` (in order) and summarizes it. Cannot fail.
[[nodiscard]] SignalHealthSummary summarize_signal_health(const std::vector<Sample>& samples,
                                                          const SignalHealthConfig& config, int p_r,
                                                          double sample_rate_hz);
/// The summary of a monitor that was fed elsewhere (call finish() first); `events`
/// are the starts and ends the caller collected, t_first/t_last [s] the span it saw.
[[nodiscard]] SignalHealthSummary summarize(const SignalHealthMonitor& monitor, std::vector<SignalFaultEvent> events,
                                            double t_first, double t_last);

}  // namespace resolver
