#include "daemon/core/discovery/breakdowns.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/model/normal_equations.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kWhitenessLags = 20;
constexpr int kCoverBins = 8;  // a 2 theta amplitude needs every eighth of a turn (coverage.h's rule for order 4)
constexpr std::int64_t kMinBinSamples = 16;

/// [1, sin k a, cos k a] for k = 1..order.
void harmonic_row(double a, int order, Eigen::VectorXd& x) {
  const double s1 = std::sin(a), c1 = std::cos(a);
  double sn = s1, cn = c1;
  x[0] = 1.0;
  for (int k = 1; k <= order; ++k) {
    x[2 * k - 1] = sn;
    x[2 * k] = cn;
    const double next = sn * c1 + cn * s1;
    cn = cn * c1 - sn * s1;
    sn = next;
  }
}

std::vector<HarmonicResidual> harmonics_of(const NormalEquations& ne, int order) {
  std::vector<HarmonicResidual> out;
  if (ne.n() < 4 * (2 * order + 1)) return out;
  const Eigen::VectorXd c = ne.m().completeOrthogonalDecomposition().solve(ne.b());
  out.push_back({0, std::abs(c[0]), c[0] >= 0.0 ? 0.0 : kPi});
  for (int k = 1; k <= order; ++k) {
    const double a = c[2 * k - 1], b = c[2 * k];
    out.push_back({k, std::hypot(a, b), std::atan2(b, a)});
  }
  return out;
}

/// A bin's rms, mean and 2 theta amplitude, with the theta coverage check.
struct Bin {
  std::int64_t n = 0;
  double sum = 0.0, sum2 = 0.0;
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  unsigned covered = 0;  // bit per eighth of a turn
  void add(double theta, double r) {
    ++n;
    sum += r;
    sum2 += r * r;
    const Eigen::Vector3d x(1.0, std::sin(2.0 * theta), std::cos(2.0 * theta));
    m += x * x.transpose();
    v += x * r;
    covered |= 1U << static_cast<unsigned>(std::clamp(static_cast<int>(wrap_2pi(theta) / kTwoPi * kCoverBins), 0,
                                                      kCoverBins - 1));
  }
  [[nodiscard]] double rms() const { return n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0; }
  [[nodiscard]] double mean() const { return n > 0 ? sum / static_cast<double>(n) : 0.0; }
  [[nodiscard]] double order2() const {
    if (covered != (1U << kCoverBins) - 1U) return kNaN;
    const Eigen::Vector3d c = m.completeOrthogonalDecomposition().solve(v);
    return std::hypot(c[1], c[2]);
  }
};


/// A row's residuals against the prediction about the nuisance constants: the
/// position-error signal and each signal group's sum of squares, counted as the fit
/// counts rows (sin/cos and dq: two per sample).
struct RowResiduals {
  bool has_position = false;
  double position = 0.0;
  double rss[3] = {0.0, 0.0, 0.0};
  std::int64_t n[3] = {0, 0, 0};
  double rd = 0.0, sa = 0.0, sr = 0.0, d = 0.0, q = 0.0;
};

RowResiduals row_residuals(const FitRow& r, const SignalValues& pred, const NuisanceValues& nuisance,
                           const PreparedLog& log) {
  RowResiduals e;
  e.rd = r.y_rd - pred.rd - nuisance.rd;
  e.sa = r.y_sa - pred.sa - nuisance.sa;
  e.sr = r.y_sr - pred.sr - nuisance.sr * (1.0 + pred.sr);  // the amplitude scales the modelled radius (design.cpp, kScGain)
  e.d = r.y_d - pred.d - nuisance.d;
  e.q = r.y_q - pred.q - nuisance.q;
  e.has_position = log.rd ? r.has(FitRow::kHasRd) : r.has(FitRow::kHasSc);
  e.position = log.rd ? e.rd : e.sa;
  if (r.has(FitRow::kHasRd)) {
    e.rss[0] = e.rd * e.rd;
    e.n[0] = 1;
  }
  if (r.has(FitRow::kHasSc)) {
    e.rss[1] = e.sa * e.sa + e.sr * e.sr;
    e.n[1] = 2;
  }
  if (r.has(FitRow::kHasCur) && log.currents) {
    e.rss[2] = e.d * e.d + e.q * e.q;
    e.n[2] = 2;
  }
  return e;
}

/// The position error binned by speed, time and direction (rms, mean, 2 theta).
class ResidualBins {
 public:
  ResidualBins(const PreparedLog& log, const DiscoveryOptions& options) {
    for (const FitRow& r : log.rows) {
      if (!r.fitted()) continue;
      wlo_ = std::min(wlo_, r.sig.omega);
      whi_ = std::max(whi_, r.sig.omega);
      tlo_ = std::min(tlo_, r.sig.t);
      thi_ = std::max(thi_, r.sig.t);
    }
    const bool speeds = (whi_ - wlo_) > 0.02 * std::max(std::abs(whi_), std::abs(wlo_));
    speed_.resize(static_cast<std::size_t>(speeds ? std::max(1, options.speed_bins) : 1));
    time_.resize(static_cast<std::size_t>(std::max(1, options.time_bins)));
  }
  void add(const FitRow& r, double res) {
    const int sbins = static_cast<int>(speed_.size()), tbins = static_cast<int>(time_.size());
    const int sb = sbins == 1 ? 0 : std::clamp(static_cast<int>((r.sig.omega - wlo_) / (whi_ - wlo_) * sbins), 0, sbins - 1);
    speed_[static_cast<std::size_t>(sb)].add(r.sig.theta, res);
    const int tb = std::clamp(static_cast<int>((r.sig.t - tlo_) / std::max(thi_ - tlo_, 1e-12) * tbins), 0, tbins - 1);
    time_[static_cast<std::size_t>(tb)].add(r.sig.theta, res);
    dir_[r.sig.direction > 0.0 ? 0 : 1].add(r.sig.theta, res);
  }
  void finish(int p_r, ResidualPass& out) const {
    const int sbins = static_cast<int>(speed_.size()), tbins = static_cast<int>(time_.size());
    for (int b = 0; b < sbins; ++b) {
      const Bin& x = speed_[static_cast<std::size_t>(b)];
      if (x.n < kMinBinSamples) continue;
      SpeedBinResidual s;
      s.omega_lo = wlo_ + (whi_ - wlo_) * b / sbins;
      s.omega_hi = wlo_ + (whi_ - wlo_) * (b + 1) / sbins;
      s.rpm_mid = 0.5 * (s.omega_lo + s.omega_hi) / p_r * 60.0 / kTwoPi;
      s.rms = x.rms();
      s.order2_amplitude = x.order2();
      s.samples = x.n;
      out.speed_bins.push_back(s);
    }
    for (int b = 0; b < tbins; ++b) {
      const Bin& x = time_[static_cast<std::size_t>(b)];
      if (x.n < kMinBinSamples) continue;
      TimeBinResidual s;
      s.t_lo = tlo_ + (thi_ - tlo_) * b / tbins;
      s.t_hi = tlo_ + (thi_ - tlo_) * (b + 1) / tbins;
      s.rms = x.rms();
      s.mean = x.mean();
      s.order2_amplitude = x.order2();
      s.samples = x.n;
      out.time_bins.push_back(s);
    }
    for (int k = 0; k < 2; ++k) {
      const Bin& x = dir_[static_cast<std::size_t>(k)];
      if (x.n == 0) continue;
      out.directions.push_back({k == 0 ? 1 : -1, x.n, x.rms(), x.mean()});
    }
  }

 private:
  double wlo_ = std::numeric_limits<double>::infinity(), whi_ = -wlo_, tlo_ = wlo_, thi_ = -wlo_;
  std::vector<Bin> speed_, time_;
  std::array<Bin, 2> dir_;
};

/// Whiteness: lagged products of the position error over runs of consecutive
/// fitted rows (a gap of 3 sample periods, an outlier or an unused row breaks a run).
class WhitenessAccumulator {
 public:
  void gap() { recent_.clear(); }
  void add(double t, double res, double sample_period) {
    if (t - prev_t_ > 3.0 * sample_period) recent_.clear();
    prev_t_ = t;
    recent_.push_back(res);
    if (recent_.size() > kWhitenessLags + 1) recent_.erase(recent_.begin());
    const std::size_t last = recent_.size() - 1;
    for (std::size_t k = 0; k <= last; ++k) {
      lag_sum_[k] += recent_[last] * recent_[last - k];
      lead_sum_[k] += recent_[last];
      lagged_sum_[k] += recent_[last - k];
      ++lag_n_[k];
    }
  }
  /// The autocorrelation of the mean-removed residual at lags 1..kWhitenessLags.
  void finish(Whiteness& w) const {
    if (lag_n_[0] <= 2 * kWhitenessLags) return;
    const double mean = lead_sum_[0] / static_cast<double>(lag_n_[0]);
    const double c0 = lag_sum_[0] / static_cast<double>(lag_n_[0]) - mean * mean;
    w.lags = kWhitenessLags;
    w.samples = lag_n_[0];
    w.band = 2.58 / std::sqrt(static_cast<double>(lag_n_[0]));
    for (int k = 1; k <= kWhitenessLags; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      if (lag_n_[kk] == 0 || !(c0 > 0.0)) continue;
      const double nk = static_cast<double>(lag_n_[kk]);
      const double ck = lag_sum_[kk] / nk - mean * (lead_sum_[kk] + lagged_sum_[kk]) / nk + mean * mean;
      const double rho = ck / c0;
      w.max_abs = std::max(w.max_abs, std::abs(rho));
      if (std::abs(rho) > w.band) ++w.outside;
    }
  }

 private:
  std::array<double, kWhitenessLags + 1> lag_sum_{}, lead_sum_{}, lagged_sum_{};
  std::array<std::int64_t, kWhitenessLags + 1> lag_n_{};
  std::vector<double> recent_;  // residuals of the current run
  double prev_t_ = -std::numeric_limits<double>::infinity();
};

/// Robust standard errors: per revolution block, the weighted score J'W r of the
/// rows on `columns`; the sum of the blocks' outer products.
class BlockScores {
 public:
  BlockScores(std::span<const int> columns, const GroupFloors& floors)
      : columns_(columns), g_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(columns.size()))), floors_(floors),
        wr_(floors.rd > 0.0 ? 1.0 / (floors.rd * floors.rd) : 0.0),
        ws_(floors.sc > 0.0 ? 1.0 / (floors.sc * floors.sc) : 0.0),
        wc_(floors.cur > 0.0 ? 1.0 / (floors.cur * floors.cur) : 0.0) {
    outer_ = Eigen::MatrixXd::Zero(g_.size(), g_.size());
  }
  /// The residuals at the solution, nuisance constants included: a constant left
  /// in would enter every block's score and inflate their spread.
  void add(const FitRow& r, const RowJacobian& jac, const RowResiduals& e) {
    if (columns_.empty()) return;
    if (r.block != block_) {
      close_block();
      block_ = r.block;
    }
    for (Eigen::Index a = 0; a < g_.size(); ++a) {
      const int c = columns_[static_cast<std::size_t>(a)];
      double s = 0.0;
      if (floors_.rd > 0.0 && r.has(FitRow::kHasRd)) s += wr_ * jac.rd[c] * e.rd;
      if (floors_.sc > 0.0 && r.has(FitRow::kHasSc)) s += ws_ * (jac.sa[c] * e.sa + jac.sr[c] * e.sr);
      if (floors_.cur > 0.0 && r.has(FitRow::kHasCur)) s += wc_ * (jac.d[c] * e.d + jac.q[c] * e.q);
      g_[a] += s;
    }
  }
  void finish(ResidualPass& out) {
    close_block();
    out.score_outer = outer_;
    out.blocks = blocks_;
  }

 private:
  void close_block() {
    if (block_ == std::numeric_limits<std::int32_t>::min()) return;
    outer_.noalias() += g_ * g_.transpose();
    ++blocks_;
    g_.setZero();
  }
  std::span<const int> columns_;
  Eigen::VectorXd g_;
  Eigen::MatrixXd outer_;
  GroupFloors floors_;
  double wr_, ws_, wc_;
  std::int32_t block_ = std::numeric_limits<std::int32_t>::min();
  int blocks_ = 0;
};

/// The plotted series: at most `points` rows, an incommensurate stride (golden-ratio
/// jitter inside each stride) so the kept samples cover the angle evenly however
/// the stride and the revolution relate.
class SeriesSampler {
 public:
  SeriesSampler(std::size_t rows, int points)
      : points_(points > 0 ? static_cast<std::size_t>(points) : 0),
        stride_(points_ > 0 ? std::max(1.0, static_cast<double>(rows) / static_cast<double>(points_)) : 0.0) {}
  /// True when row `i` is kept (then the next one is drawn).
  bool take(std::size_t i) {
    if (points_ == 0 || i < next_ || kept_ >= points_) return false;
    ++kept_;
    const double golden = std::fmod(static_cast<double>(kept_) * 0.6180339887498949, 1.0);
    next_ = static_cast<std::size_t>((static_cast<double>(kept_) + golden) * stride_);
    return true;
  }

 private:
  std::size_t points_;
  double stride_;
  std::size_t next_ = 0, kept_ = 0;
};

/// One kept row of the series: the angle error measured and modelled, and with
/// currents the dq currents raw, compensated, of the reference and modelled.
void append_series_point(const FitRow& r, const SignalValues& pred, const PreparedLog& log, ResidualSeries& s) {
  s.t.push_back(r.sig.t);
  s.theta.push_back(wrap_2pi(r.sig.theta));
  s.rpm.push_back(r.sig.omega / log.p_r * 60.0 / kTwoPi);
  s.eps_measured.push_back(log.rd ? r.y_rd : r.y_sa);
  s.eps_model.push_back(log.rd ? pred.rd : pred.sa);
  if (!r.has(FitRow::kHasCur)) return;
  // The drive's angle is the true one less the R/D error; Park at theta + delta
  // rotates (d, q) by -delta.
  auto rotate = [](double d, double q, double delta, double& od, double& oq) {
    od = d * std::cos(delta) + q * std::sin(delta);
    oq = q * std::cos(delta) - d * std::sin(delta);
  };
  const double e_per_r = static_cast<double>(log.p) / log.p_r;
  double d = 0.0, q = 0.0;
  s.theta_e.push_back(wrap_2pi(r.sig.theta_e));
  rotate(r.y_d, r.y_q, -e_per_r * r.y_rd, d, q);
  s.i_d_raw.push_back(d);
  s.i_q_raw.push_back(q);
  rotate(r.y_d, r.y_q, -e_per_r * (r.y_rd - pred.rd), d, q);
  s.i_d_comp.push_back(d);
  s.i_q_comp.push_back(q);
  s.i_d_ref.push_back(r.y_d);
  s.i_q_ref.push_back(r.y_q);
  s.i_d_model.push_back(r.sig.i_d0 + pred.d);
  s.i_q_model.push_back(r.sig.i_q0 + pred.q);
}

}  // namespace

ResidualPass residual_pass(const Design& design, const PreparedLog& log, const GroupFloors& floors,
                           std::span<const int> score_columns, const DiscoveryOptions& options,
                           std::span<const NuisanceValues> nuisance) {
  ResidualPass out;
  out.part_rss.assign(nuisance.size(), {0.0, 0.0, 0.0});
  out.part_n.assign(nuisance.size(), {0, 0, 0});
  const int order = std::max(1, options.max_report_order);
  const int hk = 2 * order + 1;
  NormalEquations h_theta(hk), h_mech(hk), h_d(hk), h_q(hk);
  Eigen::VectorXd hx(hk);
  ResidualBins bins(log, options);
  WhitenessAccumulator whiteness;
  BlockScores scores(score_columns, floors);
  SeriesSampler series(log.rows.size(), options.series_points);
  AngleBasis basis;
  SignalValues pred;
  RowJacobian jac;
  jac.resize(design.columns());
  for (std::size_t i = 0; i < log.rows.size(); ++i) {
    const FitRow& r = log.rows[i];
    if (!r.has(FitRow::kMoving) || r.has(FitRow::kExcluded)) {
      whiteness.gap();
      continue;
    }
    // The prediction evaluated: what the fit reports, not its linearised estimate.
    design.evaluate(log.rows, i, basis, pred, jac);
    const RowResiduals e = row_residuals(r, pred, nuisance[r.part], log);
    if (e.has_position) {
      out.rss_position_with_outliers += e.position * e.position;
      ++out.n_position_with_outliers;
    }
    for (int grp = 0; grp < 3; ++grp) {
      out.rss_with_outliers[grp] += e.rss[grp];
      out.n_with_outliers[grp] += e.n[grp];
    }
    if (r.has(FitRow::kOutlier)) {
      whiteness.gap();
      continue;
    }
    for (int grp = 0; grp < 3; ++grp) {
      out.rss[grp] += e.rss[grp];
      out.n[grp] += e.n[grp];
      out.part_rss[r.part][static_cast<std::size_t>(grp)] += e.rss[grp];
      out.part_n[r.part][static_cast<std::size_t>(grp)] += e.n[grp];
    }
    if (e.has_position) {
      out.rss_position += e.position * e.position;
      ++out.n_position;
      harmonic_row(r.sig.theta, order, hx);
      h_theta.add(hx, e.position);
      if (log.reference) {
        harmonic_row(r.sig.theta_m, order, hx);
        h_mech.add(hx, e.position);
      }
      bins.add(r, e.position);
      whiteness.add(r.sig.t, e.position, log.sample_period);
    }
    if (r.has(FitRow::kHasCur) && log.currents) {
      // About the operating point, so order 0 is a residual, not the mean current.
      harmonic_row(r.sig.theta_e, order, hx);
      h_d.add(hx, e.d);
      h_q.add(hx, e.q);
    }
    scores.add(r, jac, e);
    if (e.has_position && series.take(i)) append_series_point(r, pred, log, out.series);
  }
  scores.finish(out);
  out.harmonics = harmonics_of(h_theta, order);
  if (log.reference) out.harmonics_mech = harmonics_of(h_mech, order);
  if (log.currents) {
    out.harmonics_id = harmonics_of(h_d, order);
    out.harmonics_iq = harmonics_of(h_q, order);
  }
  bins.finish(log.p_r, out);
  whiteness.finish(out.whiteness);
  return out;
}

}  // namespace resolver
