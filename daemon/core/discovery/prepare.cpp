#include "daemon/core/discovery/prepare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/discovery/current_operating_point.h"
#include "daemon/core/discovery/self_calibration.h"
#include "daemon/core/estimation/dq_transform.h"

namespace resolver {

namespace {

/// Share of the samples that must carry a signal before it is used [1].
constexpr double kSignalPresentShare = 0.9;
constexpr std::int64_t kMinMovingSamples = 64;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string motion_words(const MotionSummary& m, int p_r) {
  return fmt::format("{} samples over {:.3g} s: {} moving, {} at standstill, {:.3g} mechanical revolutions "
                     "({:.3g} electrical) travelled",
                     m.samples, m.span_s, m.moving, m.standstill, m.travelled / kTwoPi, m.travelled * p_r / kTwoPi);
}

/// Validation folds (held-back residual): alternate revolutions when there are
/// enough, else the two directions, else the two halves in time.
std::string assign_folds(std::vector<FitRow>& rows, const PreparedLog& p) {
  const double mech_revs = p.motion.travelled / kTwoPi;
  const double elec_revs = mech_revs * p.p_r;
  double travel = 0.0;
  const bool by_mech = mech_revs >= 4.0;
  const bool by_elec = !by_mech && elec_revs >= 4.0;
  const bool by_direction = !by_mech && !by_elec && p.motion.forward > 0 && p.motion.backward > 0;
  std::int64_t moving_seen = 0;
  const std::int64_t half = p.motion.moving / 2;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    FitRow& r = rows[i];
    if (i > 0 && r.has(FitRow::kMoving) && rows[i - 1].has(FitRow::kMoving)) {
      travel += std::abs(r.sig.theta_m - rows[i - 1].sig.theta_m);
    }
    bool b = false;
    if (by_mech) b = static_cast<std::int64_t>(travel / kTwoPi) % 2 == 1;
    else if (by_elec) b = static_cast<std::int64_t>(travel * p.p_r / kTwoPi) % 2 == 1;
    else if (by_direction) b = r.sig.direction < 0.0;
    else b = moving_seen >= half;
    if (r.has(FitRow::kMoving)) ++moving_seen;
    if (b) r.flags |= FitRow::kFoldB;
    r.block = static_cast<std::int32_t>(travel * p.p_r / kTwoPi);
  }
  if (by_mech) return "alternate mechanical revolutions";
  if (by_elec) return "alternate electrical revolutions";
  if (by_direction) return "forward against backward";
  return "first half against second half of the moving samples";
}

/// sin/cos pairs that do not circle zero (unipolar ADC counts with their mid-scale
/// bias still in) give an angle that never turns: every later figure would be
/// about an artefact. The offsets effect models small DC offsets (a fraction of the
/// amplitude), not a bias larger than the swing, so this is an input error.
void check_sincos_centred(const std::vector<Sample>& samples) {
  double ms = 0.0, mc = 0.0;
  std::size_t n = 0;
  for (const Sample& x : samples) {
    if (!x.has_sincos) continue;
    ms += x.sin;
    mc += x.cos;
    ++n;
  }
  if (n == 0) return;
  ms /= static_cast<double>(n);
  mc /= static_cast<double>(n);
  // Mean and spread of the radius about the centre and about zero: a centred pair
  // that turns only part of the way (an arc) has its mean off zero too, but its
  // radius about zero stays constant; a biased pair's radius does not.
  double swing = 0.0, swing2 = 0.0, r0 = 0.0, r02 = 0.0;
  for (const Sample& x : samples) {
    if (!x.has_sincos) continue;
    const double rc = std::hypot(x.sin - ms, x.cos - mc), rz = std::hypot(x.sin, x.cos);
    swing += rc;
    swing2 += rc * rc;
    r0 += rz;
    r02 += rz * rz;
  }
  const auto nd = static_cast<double>(n);
  swing /= nd;
  r0 /= nd;
  const double spread_centre = std::sqrt(std::max(0.0, swing2 / nd - swing * swing)) / std::max(swing, 1e-300);
  const double spread_zero = std::sqrt(std::max(0.0, r02 / nd - r0 * r0)) / std::max(r0, 1e-300);
  // Half the swing: the offsets effect's regressors are linearised about zero and
  // lose meaning long before the centre leaves the circle.
  if (std::hypot(ms, mc) > 0.5 * swing && spread_zero > spread_centre) {
    throw std::invalid_argument(fmt::format(
        "the sin/cos pair does not circle zero: its centre is sin {:.6g}, cos {:.6g} against a swing of {:.6g} "
        "(unipolar ADC counts with their bias still in?); subtract the bias in the input, e.g. [input.csv.columns] "
        "sin = {{ ..., offset = {:.6g} }}, cos = {{ ..., offset = {:.6g} }}, or the DBC signal's offset",
        ms, mc, swing, -ms, -mc));
  }
}

/// The measured angles must turn with the reference, p_r electrical turns per
/// mechanical one. A channel wired the other way (or sin and cos swapped) makes the
/// sin/cos angle run backwards, a reference mounted the other way or another ratio
/// makes every sample's error grow with the angle: no catalog effect is either, and a
/// fit would be nonsense at hundreds of times the floor (issue 21), so this is an
/// input error naming the fix. Judged on the summed wrapped steps of moving samples
/// where the reference steps less than pi/4 electrical per sample (no aliasing).
void check_turns_with_reference(const std::vector<const Sample*>& s, const std::vector<double>& theta,
                                const std::vector<MotionSample>& motion, bool rd, bool sincos, int p_r) {
  double ref = 0.0, r = 0.0, sc = 0.0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (!motion[i].moving) continue;
    const double dref = theta[i] - theta[i - 1];
    if (!(std::abs(dref) < 0.25 * kPi)) continue;
    ref += dref;
    if (rd && s[i]->has_rd && s[i - 1]->has_rd) r += wrap_pi(s[i]->theta_rd - s[i - 1]->theta_rd);
    if (sincos && s[i]->has_sincos && s[i - 1]->has_sincos) {
      sc += wrap_pi(std::atan2(s[i]->sin, s[i]->cos) - std::atan2(s[i - 1]->sin, s[i - 1]->cos));
    }
  }
  // Half an electrical turn of net travel tells a direction; less is a note-free pass.
  if (!(std::abs(ref) > kPi)) return;
  const auto judge = [&](double travel, const char* what, const char* fix_reversed) {
    // A dead or frozen channel turns ~0 times: a fault for signal health to report,
    // not wiring. Only ratios a miswired or misconfigured bench gives are named.
    const double ratio = travel / ref;
    if (ratio < -0.5 && ratio > -5.0) {
      throw std::invalid_argument(fmt::format(
          "the {} turns the other way from the reference ({:.3g} electrical turns against the reference's {:.3g} "
          "x p_r = {}): {}",
          what, travel / kTwoPi, ref / kTwoPi, p_r, fix_reversed));
    }
    if (std::abs(ratio - 1.0) > 0.05 && ratio > 0.2 && ratio < 5.0) {
      throw std::invalid_argument(fmt::format(
          "the {} turns {:.4g} times as far as the reference x p_r = {} ({:.3g} against {:.3g} electrical turns): "
          "the resolver's pole pairs are p_r = {:.4g}? set [bench] p_r (or the reference's ratio: [input.csv.columns] "
          "ref_angle divide = N)",
          what, ratio, p_r, travel / kTwoPi, ref / kTwoPi, ratio * p_r));
    }
  };
  if (rd) {
    judge(r, "R/D angle",
          "the reference or the R/D angle counts the other way: negate one (CSV column scale = -1, or the DBC "
          "signal's factor)");
  }
  if (sincos) {
    judge(sc, "sin/cos angle atan2(sin, cos)",
          "one channel is wired with the opposite sign, or sin and cos are swapped: negate one channel (CSV column "
          "scale = -1, or the DBC signal's factor) or swap the sin and cos roles");
  }
}


/// Which signals the log carries (each in at least 90 % of its samples), and the
/// notes on what that leaves out. Returns whether phase currents are there.
bool detect_signals(const DiscoveryInput& in, const PrepareOptions& opt, PreparedLog& p) {
  std::size_t with_rd = 0, with_sc = 0, with_ref = 0, with_cur = 0;
  for (const Sample& s : in.samples) {
    with_rd += s.has_rd ? 1 : 0;
    with_sc += s.has_sincos ? 1 : 0;
    with_ref += s.has_ref ? 1 : 0;
    with_cur += s.has_currents ? 1 : 0;
  }
  const double total = static_cast<double>(std::max<std::size_t>(in.samples.size(), 1));
  p.rd = static_cast<double>(with_rd) >= kSignalPresentShare * total;
  p.sincos = static_cast<double>(with_sc) >= kSignalPresentShare * total;
  p.reference = static_cast<double>(with_ref) >= kSignalPresentShare * total;
  p.reference_aligned = p.reference && opt.reference_aligned;
  const bool currents = static_cast<double>(with_cur) >= kSignalPresentShare * total;
  if (!p.rd && !p.sincos) {
    throw std::invalid_argument(fmt::format(
        "no angle signal: of {} samples {} carry an R/D angle and {} sin/cos envelopes (a signal is used when at "
        "least 90 % of the samples carry it); check the layout's signal map",
        in.samples.size(), with_rd, with_sc));
  }
  if (p.sincos) check_sincos_centred(in.samples);
  if (!p.reference) {
    p.notes.emplace_back(
        "no reference angle: fitting against the self-calibrated ideal angle (constant errors, delay, backlash, "
        "mounting offset and mechanical orders are not identifiable)");
  }
  if (p.reference && !p.reference_aligned) {
    p.notes.emplace_back(
        "the reference's zero against the resolver's is a free constant of the fit (nuisance.rd_constant); "
        "mounting_offset needs [bench] reference_aligned = true (the reference encoder's zero set on the rotor "
        "d axis, as resolver-sim's is)");
  }
  if (!p.sincos) p.notes.emplace_back("no sin/cos envelopes: only the R/D angle is fitted (k3 and alpha, k2 and "
                                      "offsets, land on the same orders and are told apart only by sin/cos)");
  if (!p.rd) p.notes.emplace_back("no R/D angle: the position error is the sin/cos angle's");
  if (!currents) p.notes.emplace_back("no phase currents in the log: current-side effects are not evaluated");
  else if (!p.reference) p.notes.emplace_back("phase currents present but not fitted without a reference angle (dq needs the true theta_e)");
  return currents;
}

/// The samples the fit can use: a primary angle, and the reference in reference
/// mode (the others counted in `p`).
std::vector<const Sample*> usable_samples(const DiscoveryInput& in, PreparedLog& p) {
  std::vector<const Sample*> s;
  s.reserve(in.samples.size());
  for (const Sample& x : in.samples) {
    const bool angle = p.rd ? x.has_rd : x.has_sincos;
    if (!angle) {
      ++p.without_angle;
      continue;
    }
    if (p.reference && !x.has_ref) {
      ++p.without_reference;
      continue;
    }
    s.push_back(&x);
  }
  if (s.size() < static_cast<std::size_t>(kMinMovingSamples)) {
    throw std::invalid_argument(fmt::format("too few samples with an angle ({}): nothing to fit", s.size()));
  }
  return s;
}

/// [s] each sample's time from the origin (the first sample's, or PrepareOptions::
/// time_origin for a later chunk of a log); sets the origin and the median sample period.
std::vector<double> sample_times(const std::vector<const Sample*>& s, const PrepareOptions& opt, PreparedLog& p) {
  const std::size_t n = s.size();
  std::vector<double> t(n), dts;
  p.time_origin = std::isfinite(opt.time_origin) ? opt.time_origin : s.front()->t;
  for (std::size_t i = 0; i < n; ++i) t[i] = s[i]->t - p.time_origin;
  dts.reserve(n);
  for (std::size_t i = 1; i < n; ++i) dts.push_back(t[i] - t[i - 1]);
  p.sample_period = std::max(median(dts), 1e-9);
  return t;
}

/// Envelope amplitude [counts]: the median radius (robust to outliers and clipping), or
/// the one the options give (a later chunk of a log: PrepareOptions::amplitude).
void measure_amplitude(const std::vector<const Sample*>& s, const PrepareOptions& opt, PreparedLog& p) {
  std::vector<double> radius;
  radius.reserve(s.size());
  for (const Sample* x : s) {
    if (x->has_sincos) radius.push_back(std::hypot(x->sin, x->cos));
  }
  p.amplitude = median(radius);
  if (!(p.amplitude > 0.0)) {
    p.sincos = false;
    p.notes.emplace_back("sin/cos envelopes are zero: loss of signal; the sin/cos rows are not fitted");
  } else if (opt.amplitude > 0.0) {
    p.amplitude = opt.amplitude;
  }
}

/// The true angle of every sample and the motion: from the reference, or else
/// self-calibrated from the primary angle.
struct TrueAngles {
  std::vector<double> theta, theta_m;
  std::vector<MotionSample> motion;
  std::vector<bool> usable;
};

TrueAngles true_angles(const std::vector<const Sample*>& s, const std::vector<double>& t, const PrepareOptions& opt,
                       PreparedLog& p) {
  const std::size_t n = s.size();
  TrueAngles a{std::vector<double>(n), std::vector<double>(n), {}, std::vector<bool>(n, true)};
  if (p.reference) {
    AngleUnwrapper un;
    for (std::size_t i = 0; i < n; ++i) {
      a.theta_m[i] = un.update(wrap_2pi(s[i]->theta_m_ref));
      a.theta[i] = p.p_r * a.theta_m[i];
    }
    a.motion = analyse_motion(t, a.theta_m, p.motion, opt.continuation.valid ? opt.continuation.direction : 0.0);
    check_turns_with_reference(s, a.theta, a.motion, p.rd, p.sincos, p.p_r);
  } else {
    std::vector<double> primary(n), cont(n), mech(n);
    AngleUnwrapper un;
    for (std::size_t i = 0; i < n; ++i) {
      primary[i] = p.rd ? wrap_2pi(s[i]->theta_rd) : wrap_2pi(std::atan2(s[i]->sin, s[i]->cos));
      cont[i] = un.update(primary[i]);
      mech[i] = cont[i] / p.p_r;
    }
    MotionSummary raw_motion;
    const std::vector<MotionSample> raw = analyse_motion(t, mech, raw_motion);
    const SelfCalibration cal = self_calibrate(t, cont, primary, raw, p.sample_period);
    p.unusable_self_calibration = cal.unusable;
    for (std::size_t i = 0; i < n; ++i) {
      a.theta[i] = cal.ideal[i];
      a.theta_m[i] = a.theta[i] / p.p_r;
      a.usable[i] = cal.usable[i];
    }
    a.motion = analyse_motion(t, a.theta_m, p.motion);
    if (cal.unusable > 0) {
      p.notes.push_back(fmt::format("{} moving samples are in stretches shorter than one electrical revolution: "
                                    "without a reference they cannot be self-calibrated and are not fitted",
                                    cal.unusable));
    }
  }
  if (p.motion.moving < kMinMovingSamples) {
    throw std::invalid_argument(fmt::format("the rotor hardly moves: {}; at least {} moving samples are needed",
                                            motion_words(p.motion, p.p_r), kMinMovingSamples));
  }
  return a;
}

/// [rad, mechanical] travel since the last reversal, from its turning point
/// (backlash's take-up); infinity before the first reversal. Goes on from where an
/// earlier chunk left the rotor (`in`, when valid) and says where these samples leave it (`out`).
std::vector<double> travel_since_reversal(const TrueAngles& a, const MotionContinuation& in, MotionContinuation& out) {
  const std::size_t n = a.theta_m.size();
  std::vector<double> since(n, std::numeric_limits<double>::infinity());
  if (n == 0) return since;
  double held = a.motion.front().direction;
  double extremum = a.theta_m.front();
  double turning = 0.0;
  bool reversed = false;
  if (in.valid) {
    // The earlier chunk's last sample in this chunk's unwrapped angle: the rotor moves
    // less than half a turn between two samples.
    const double before = a.theta_m.front() - wrap_pi(wrap_2pi(a.theta_m.front()) - in.last_angle);
    held = in.direction;
    extremum = before + in.extremum_offset;
    turning = before + in.turning_offset;
    reversed = in.reversed;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (a.motion[i].direction != held) {
      turning = extremum;
      reversed = true;
      held = a.motion[i].direction;
      extremum = a.theta_m[i];
    }
    extremum = held > 0.0 ? std::max(extremum, a.theta_m[i]) : std::min(extremum, a.theta_m[i]);
    if (reversed) since[i] = std::abs(a.theta_m[i] - turning);
  }
  out = {.valid = true,
         .direction = held,
         .last_angle = wrap_2pi(a.theta_m.back()),
         .reversed = reversed,
         .turning_offset = turning - a.theta_m.back(),
         .extremum_offset = extremum - a.theta_m.back()};
  return since;
}

/// One fit row per usable sample: its angles and motion, which rows are fitted,
/// and the measured errors of every signal.
void build_rows(const DiscoveryInput& in, const std::vector<const Sample*>& s, const std::vector<double>& t,
                const TrueAngles& a, bool currents, const PrepareOptions& opt, PreparedLog& p) {
  const std::size_t n = s.size();
  // Without a reference each chunk's angle has its own zero: nothing to go on from.
  const std::vector<double> since =
      travel_since_reversal(a, p.reference ? opt.continuation : MotionContinuation{}, p.continuation);
  if (!p.reference) p.continuation = {};
  p.rows.resize(n);
  p.sample_of_row.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.sample_of_row[i] = static_cast<std::size_t>(s[i] - in.samples.data());
  for (std::size_t i = 0; i < n; ++i) {
    FitRow& r = p.rows[i];
    const Sample& x = *s[i];
    const MotionSample& m = a.motion[i];
    r.sig.t = t[i];
    r.sig.theta = a.theta[i];
    r.sig.theta_m = a.theta_m[i];
    r.sig.omega = m.omega * p.p_r;
    r.sig.accel = m.accel * p.p_r;
    r.sig.direction = m.direction;
    r.sig.since_reversal = since[i];
    r.sig.p_r = p.p_r;
    r.sig.p = p.p;
    if (m.moving && a.usable[i]) r.flags |= FitRow::kMoving;
    const bool wrong_way = (opt.direction == DirectionFilter::kForward && m.direction < 0.0) ||
                           (opt.direction == DirectionFilter::kBackward && m.direction > 0.0);
    if (wrong_way && r.has(FitRow::kMoving)) {
      r.flags &= static_cast<std::uint16_t>(~FitRow::kMoving);
      r.flags |= FitRow::kExcluded;
      ++p.excluded_direction;
    }
    if (opt.moving_only && !r.has(FitRow::kMoving)) r.flags |= FitRow::kExcluded;
    if (!a.usable[i]) r.flags |= FitRow::kExcluded;
    if (p.rd && x.has_rd) {
      r.y_rd = wrap_pi(a.theta[i] - x.theta_rd);
      r.flags |= FitRow::kHasRd;
    }
    if (p.sincos && x.has_sincos) {
      r.y_sa = wrap_pi(a.theta[i] - std::atan2(x.sin, x.cos));
      r.y_sr = std::hypot(x.sin, x.cos) / p.amplitude - 1.0;
      r.flags |= FitRow::kHasSc;
    }
    if (currents && p.reference && x.has_currents) {
      r.sig.theta_e = p.p * a.theta_m[i];
      const ClarkeTransform ab(x.i_a, x.i_b, x.i_c);
      const ParkTransform dq(ab.alpha, ab.beta, r.sig.theta_e);
      r.y_d = dq.d;
      r.y_q = dq.q;
      r.flags |= FitRow::kHasCur;
    }
  }
}

/// Whether any moving row has the currents (what the fit and the outlier scan use).
bool moving_currents(const PreparedLog& p) {
  return std::any_of(p.rows.begin(), p.rows.end(),
                     [](const FitRow& r) { return r.has(FitRow::kHasCur) && r.has(FitRow::kMoving); });
}

/// The operating point of the currents: the constant of i_d, i_q over the moving rows
/// with the effects' ripple fitted out (current_operating_point.h), given to every row.
/// Outliers left out: one-sided spikes (a current ADC that glitches high) would shift it
/// by their rate x size / sample rate, a current offset the gains' prediction then carries.
void set_current_operating_point(PreparedLog& p) {
  CurrentOperatingPointFit fit;
  for (const FitRow& r : p.rows) {
    if (!r.has(FitRow::kHasCur) || !r.has(FitRow::kMoving) || r.has(FitRow::kOutlier)) continue;
    fit.add(r.sig.theta_e, r.y_d, r.y_q);
  }
  const CurrentOperatingPoint op = fit.result();
  if (!op.ripple_separated) {
    p.notes.emplace_back(
        "the moving samples cover too little of the motor's electrical angle to tell the currents' ripple from "
        "their operating point: it is their mean, and current-side effects' values may carry part of the ripple");
  }
  for (FitRow& r : p.rows) {
    r.sig.i_d0 = op.i_d;
    r.sig.i_q0 = op.i_q;
  }
}

/// A position error is known modulo 2 pi. Near +-pi (a reference whose zero is
/// half a turn from the resolver's: any real bench's encoder) wrapping to
/// (-pi, pi] would cut the error in two; put the cut opposite its circular mean.
void recenter(PreparedLog& p, FitRow::Flag has, double FitRow::*field) {
  double sx = 0.0, sy = 0.0;
  for (const FitRow& r : p.rows) {
    if (!r.has(has)) continue;
    sx += std::cos(r.*field);
    sy += std::sin(r.*field);
  }
  if (sx == 0.0 && sy == 0.0) return;
  const double centre = std::atan2(sy, sx);
  for (FitRow& r : p.rows) {
    if (r.has(has)) r.*field = centre + wrap_pi(r.*field - centre);
  }
}

/// Outliers, per signal over consecutive samples: flagged rows, counted per signal. Each
/// signal is tested on its own (a row one flagged is a clean neighbour to the others: a
/// spike on sin leaves the currents of its row as they were) and counts every spike it
/// has; a row any flags is out of the fit.
void flag_outliers(const std::vector<double>& t, PreparedLog& p) {
  const std::size_t n = p.rows.size();
  std::vector<bool> flags(n, false), own(n), ok(n);
  auto take = [&] {
    for (std::size_t i = 0; i < n; ++i) flags[i] = flags[i] || own[i];
  };
  std::vector<double> y(n);
  auto merge = [&](OutlierSignal o) {
    if (o.count == 0) return;
    for (OutlierSignal& e : p.outliers) {
      if (e.signal != o.signal) continue;
      e.count += o.count;
      e.largest = std::max(e.largest, o.largest);
      return;
    }
    p.outliers.push_back(std::move(o));
  };
  auto scan = [&](FitRow::Flag has, double FitRow::*field, const std::string& name) {
    for (std::size_t i = 0; i < n; ++i) {
      ok[i] = p.rows[i].has(has) && !p.rows[i].has(FitRow::kExcluded);
      y[i] = p.rows[i].*field;
    }
    own.assign(n, false);
    merge(find_outliers(t, y, ok, own, name));
    take();
  };
  if (p.rd) scan(FitRow::kHasRd, &FitRow::y_rd, "position_error");
  // Two components of one signal judged together by the burst test (outliers.h).
  std::vector<double> y2(n);
  auto scan_bursts = [&](FitRow::Flag has, double FitRow::*a, double FitRow::*b, const std::string& name) {
    for (std::size_t i = 0; i < n; ++i) {
      ok[i] = p.rows[i].has(has) && !p.rows[i].has(FitRow::kExcluded);
      y[i] = p.rows[i].*a;
      y2[i] = p.rows[i].*b;
    }
    const std::array<std::span<const double>, 2> ys{y, y2};
    own.assign(n, false);
    merge(find_outlier_bursts(t, ys, ok, own, name));
    take();
  };
  // The sin/cos ADC's spikes (EMI on the resolver's cable) come in bursts and at runs'
  // ends like the currents' (outliers.h); a missed 15 % spike is ~1000 times the floor.
  if (p.sincos) scan_bursts(FitRow::kHasSc, &FitRow::y_sa, &FitRow::y_sr, "sin_cos");
  // The currents' spikes (switching EMI on their ADCs); a missed 10 A spike is 500 times
  // their floor.
  if (p.currents) scan_bursts(FitRow::kHasCur, &FitRow::y_d, &FitRow::y_q, "i_dq");
  for (std::size_t i = 0; i < n; ++i) {
    if (flags[i]) p.rows[i].flags |= FitRow::kOutlier;
  }
}

/// The raw channels' quanta and every signal's noise floor; a signal whose floor
/// cannot be estimated is not fitted (the position error's is required).
void measure_floors(const std::vector<const Sample*>& s, const PrepareOptions& opt, PreparedLog& p) {
  std::vector<double> v;
  v.reserve(s.size());
  auto quantum = [&](auto get) {
    v.clear();
    for (const Sample* x : s) v.push_back(get(*x));
    return channel_quantum(v);
  };
  if (p.rd) p.quanta.rd = quantum([](const Sample& x) { return wrap_2pi(x.theta_rd); });
  if (p.reference) p.quanta.ref = p.p_r * quantum([](const Sample& x) { return wrap_2pi(x.theta_m_ref); });
  if (p.sincos) {
    p.quanta.sincos = quantum([](const Sample& x) { return x.sin; });
    p.quanta.amplitude = p.amplitude;
  }
  p.floors = estimate_floors(p.rows, p.sample_period, p.reference, p.quanta, !opt.moving_only);
  if (p.rd && !(p.floors.rd.chosen > 0.0)) {
    throw std::invalid_argument("could not estimate the noise floor of the position error (too few consecutive "
                                "moving samples per speed)");
  }
  if (p.sincos && !(p.floors.sc.chosen > 0.0)) {
    p.sincos = false;
    p.notes.emplace_back("sin/cos floor could not be estimated: sin/cos not fitted");
  }
  if (p.currents && !(p.floors.cur.chosen > 0.0)) {
    p.currents = false;
    p.notes.emplace_back("phase currents present but their noise floor could not be estimated: not fitted");
  }
}

}  // namespace

std::int64_t PreparedLog::fitted_rows() const {
  return std::count_if(rows.begin(), rows.end(), [](const FitRow& r) { return r.fitted(); });
}

std::int64_t PreparedLog::outlier_rows() const {
  return std::count_if(rows.begin(), rows.end(), [](const FitRow& r) { return r.has(FitRow::kOutlier); });
}

double PreparedLog::electrical_revolutions() const { return motion.travelled * p_r / kTwoPi; }

PreparedLog prepare_log(const DiscoveryInput& in, const PrepareOptions& opt) {
  if (in.p_r < 1 || in.p < 1) {
    throw std::invalid_argument(fmt::format("pole pairs p_r = {} and p = {} must be >= 1", in.p_r, in.p));
  }
  PreparedLog p;
  p.p_r = in.p_r;
  p.p = in.p;
  p.samples_in = static_cast<std::int64_t>(in.samples.size());
  const bool currents = detect_signals(in, opt, p);
  const std::vector<const Sample*> s = usable_samples(in, p);
  const std::vector<double> t = sample_times(s, opt, p);
  if (p.sincos) measure_amplitude(s, opt, p);
  const TrueAngles angles = true_angles(s, t, opt, p);
  build_rows(in, s, t, angles, currents, opt, p);
  p.currents = moving_currents(p);
  if (p.rd) recenter(p, FitRow::kHasRd, &FitRow::y_rd);
  if (p.sincos) recenter(p, FitRow::kHasSc, &FitRow::y_sa);
  flag_outliers(t, p);
  if (p.currents) set_current_operating_point(p);
  p.fold_rule = assign_folds(p.rows, p);
  measure_floors(s, opt, p);
  return p;
}

}  // namespace resolver
