#include "daemon/core/discovery/breakdowns.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

}  // namespace

ResidualPass residual_pass(const Design& design, const PreparedLog& log, const GroupFloors& floors,
                           std::span<const int> score_columns, const DiscoveryOptions& options,
                           const NuisanceValues& nuisance) {
  ResidualPass out;
  const double sa_offset = nuisance.sa, sr_offset = nuisance.sr, d_offset = nuisance.d, q_offset = nuisance.q;
  const int order = std::max(1, options.max_report_order);
  const int hk = 2 * order + 1;
  NormalEquations h_theta(hk), h_mech(hk), h_d(hk), h_q(hk);
  Eigen::VectorXd hx(hk);
  const bool position_rd = log.rd;
  // Speed bins over the signed speeds of the fitted rows.
  double wlo = std::numeric_limits<double>::infinity(), whi = -wlo, tlo = wlo, thi = -wlo;
  std::int64_t fitted = 0;
  for (const FitRow& r : log.rows) {
    if (!r.fitted()) continue;
    wlo = std::min(wlo, r.sig.omega);
    whi = std::max(whi, r.sig.omega);
    tlo = std::min(tlo, r.sig.t);
    thi = std::max(thi, r.sig.t);
    ++fitted;
  }
  const int sbins = (whi - wlo) > 0.02 * std::max(std::abs(whi), std::abs(wlo)) ? std::max(1, options.speed_bins) : 1;
  const int tbins = std::max(1, options.time_bins);
  std::vector<Bin> speed(static_cast<std::size_t>(sbins)), time(static_cast<std::size_t>(tbins)), dir(2);
  // Whiteness: lagged products over consecutive fitted rows.
  std::vector<double> lag_sum(kWhitenessLags + 1, 0.0), lead_sum(kWhitenessLags + 1, 0.0),
      lagged_sum(kWhitenessLags + 1, 0.0);
  std::vector<std::int64_t> lag_n(kWhitenessLags + 1, 0);
  std::vector<double> recent;  // residuals of the current run of consecutive fitted rows
  // Robust errors: per-block scores.
  const auto sk = static_cast<Eigen::Index>(score_columns.size());
  out.score_outer = Eigen::MatrixXd::Zero(sk, sk);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(sk);
  std::int32_t block = std::numeric_limits<std::int32_t>::min();
  auto close_block = [&]() {
    if (block == std::numeric_limits<std::int32_t>::min()) return;
    out.score_outer.noalias() += g * g.transpose();
    ++out.blocks;
    g.setZero();
  };
  const double wr = floors.rd > 0.0 ? 1.0 / (floors.rd * floors.rd) : 0.0;
  const double ws = floors.sc > 0.0 ? 1.0 / (floors.sc * floors.sc) : 0.0;
  const double wc = floors.cur > 0.0 ? 1.0 / (floors.cur * floors.cur) : 0.0;
  // Series: an incommensurate stride (golden-ratio jitter inside each stride) so the
  // kept samples cover the angle evenly however the stride and the revolution relate.
  const std::size_t n = log.rows.size();
  const std::size_t points = options.series_points > 0 ? static_cast<std::size_t>(options.series_points) : 0;
  const double stride = points > 0 ? std::max(1.0, static_cast<double>(n) / static_cast<double>(points)) : 0.0;
  std::size_t next_kept = 0, kept = 0;
  const double e_per_r = static_cast<double>(log.p) / log.p_r;
  AngleBasis basis;
  SignalValues pred;
  RowJacobian jac;
  jac.resize(design.columns());
  double prev_t = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const FitRow& r = log.rows[i];
    const bool usable = r.has(FitRow::kMoving) && !r.has(FitRow::kExcluded);
    if (!usable) {
      recent.clear();
      continue;
    }
    design.evaluate(log.rows, i, basis, pred, jac);
    const bool has_pos = position_rd ? r.has(FitRow::kHasRd) : r.has(FitRow::kHasSc);
    const double res_pos = position_rd ? r.y_rd - pred.rd - nuisance.rd : r.y_sa - pred.sa - sa_offset;
    if (has_pos) {
      out.rss_position_with_outliers += res_pos * res_pos;
      ++out.n_position_with_outliers;
    }
    // Per group, as the fit counts rows (sin/cos and dq: two per sample), with the
    // prediction evaluated: what the fit reports, not its linearised estimate.
    double group_rss[3] = {0.0, 0.0, 0.0};
    std::int64_t group_n[3] = {0, 0, 0};
    if (r.has(FitRow::kHasRd)) {
      const double er = r.y_rd - pred.rd - nuisance.rd;
      group_rss[0] = er * er;
      group_n[0] = 1;
    }
    if (r.has(FitRow::kHasSc)) {
      // The amplitude scales the modelled radius (design.cpp, kScGain).
      const double ea = r.y_sa - pred.sa - sa_offset, er = r.y_sr - pred.sr - sr_offset * (1.0 + pred.sr);
      group_rss[1] = ea * ea + er * er;
      group_n[1] = 2;
    }
    if (r.has(FitRow::kHasCur) && log.currents) {
      const double ed = r.y_d - pred.d - d_offset, eq = r.y_q - pred.q - q_offset;
      group_rss[2] = ed * ed + eq * eq;
      group_n[2] = 2;
    }
    for (int grp = 0; grp < 3; ++grp) {
      out.rss_with_outliers[grp] += group_rss[grp];
      out.n_with_outliers[grp] += group_n[grp];
    }
    if (r.has(FitRow::kOutlier)) {
      recent.clear();
      continue;
    }
    for (int grp = 0; grp < 3; ++grp) {
      out.rss[grp] += group_rss[grp];
      out.n[grp] += group_n[grp];
    }
    if (has_pos) {
      out.rss_position += res_pos * res_pos;
      ++out.n_position;
      harmonic_row(r.sig.theta, order, hx);
      h_theta.add(hx, res_pos);
      if (log.reference) {
        harmonic_row(r.sig.theta_m, order, hx);
        h_mech.add(hx, res_pos);
      }
      const int sb = sbins == 1 ? 0 : std::clamp(static_cast<int>((r.sig.omega - wlo) / (whi - wlo) * sbins), 0, sbins - 1);
      speed[static_cast<std::size_t>(sb)].add(r.sig.theta, res_pos);
      const int tb = std::clamp(static_cast<int>((r.sig.t - tlo) / std::max(thi - tlo, 1e-12) * tbins), 0, tbins - 1);
      time[static_cast<std::size_t>(tb)].add(r.sig.theta, res_pos);
      dir[r.sig.direction > 0.0 ? 0 : 1].add(r.sig.theta, res_pos);
      // Whiteness over consecutive samples (a gap of 3 sample periods breaks the run).
      if (r.sig.t - prev_t > 3.0 * log.sample_period) recent.clear();
      prev_t = r.sig.t;
      recent.push_back(res_pos);
      if (recent.size() > kWhitenessLags + 1) recent.erase(recent.begin());
      const std::size_t last = recent.size() - 1;
      for (std::size_t k = 0; k <= last; ++k) {
        lag_sum[k] += recent[last] * recent[last - k];
        lead_sum[k] += recent[last];
        lagged_sum[k] += recent[last - k];
        ++lag_n[k];
      }
    }
    if (r.has(FitRow::kHasCur) && log.currents) {
      // About the operating point, so order 0 is a residual, not the mean current.
      harmonic_row(r.sig.theta_e, order, hx);
      h_d.add(hx, r.y_d - pred.d - d_offset);
      h_q.add(hx, r.y_q - pred.q - q_offset);
    }
    // Robust standard errors: the weighted score of the row on the model's columns.
    if (sk > 0) {
      if (r.block != block) {
        close_block();
        block = r.block;
      }
      for (Eigen::Index a = 0; a < sk; ++a) {
        const int c = score_columns[static_cast<std::size_t>(a)];
        double s = 0.0;
        // The residuals at the solution, nuisance constants included: a constant left in
        // would enter every block's score and inflate their spread.
        if (floors.rd > 0.0 && r.has(FitRow::kHasRd)) s += wr * jac.rd[c] * (r.y_rd - pred.rd - nuisance.rd);
        if (floors.sc > 0.0 && r.has(FitRow::kHasSc)) {
          s += ws * (jac.sa[c] * (r.y_sa - pred.sa - sa_offset) +
                     jac.sr[c] * (r.y_sr - pred.sr - sr_offset * (1.0 + pred.sr)));
        }
        if (floors.cur > 0.0 && r.has(FitRow::kHasCur)) {
          s += wc * (jac.d[c] * (r.y_d - pred.d - d_offset) + jac.q[c] * (r.y_q - pred.q - q_offset));
        }
        g[a] += s;
      }
    }
    if (points > 0 && i >= next_kept && kept < points && has_pos) {
      ++kept;
      const double golden = std::fmod(static_cast<double>(kept) * 0.6180339887498949, 1.0);
      next_kept = static_cast<std::size_t>((static_cast<double>(kept) + golden) * stride);
      ResidualSeries& s = out.series;
      s.t.push_back(r.sig.t);
      s.theta.push_back(wrap_2pi(r.sig.theta));
      s.rpm.push_back(r.sig.omega / log.p_r * 60.0 / kTwoPi);
      s.eps_measured.push_back(position_rd ? r.y_rd : r.y_sa);
      s.eps_model.push_back(position_rd ? pred.rd : pred.sa);
      if (r.has(FitRow::kHasCur)) {
        // The drive's angle is the true one less the R/D error; Park at theta + delta
        // rotates (d, q) by -delta.
        auto rotate = [](double d, double q, double delta, double& od, double& oq) {
          od = d * std::cos(delta) + q * std::sin(delta);
          oq = q * std::cos(delta) - d * std::sin(delta);
        };
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
    }
  }
  close_block();
  out.harmonics = harmonics_of(h_theta, order);
  if (log.reference) out.harmonics_mech = harmonics_of(h_mech, order);
  if (log.currents) {
    out.harmonics_id = harmonics_of(h_d, order);
    out.harmonics_iq = harmonics_of(h_q, order);
  }
  for (int b = 0; b < sbins; ++b) {
    const Bin& x = speed[static_cast<std::size_t>(b)];
    if (x.n < kMinBinSamples) continue;
    SpeedBinResidual s;
    s.omega_lo = wlo + (whi - wlo) * b / sbins;
    s.omega_hi = wlo + (whi - wlo) * (b + 1) / sbins;
    s.rpm_mid = 0.5 * (s.omega_lo + s.omega_hi) / log.p_r * 60.0 / kTwoPi;
    s.rms = x.rms();
    s.order2_amplitude = x.order2();
    s.samples = x.n;
    out.speed_bins.push_back(s);
  }
  for (int b = 0; b < tbins; ++b) {
    const Bin& x = time[static_cast<std::size_t>(b)];
    if (x.n < kMinBinSamples) continue;
    TimeBinResidual s;
    s.t_lo = tlo + (thi - tlo) * b / tbins;
    s.t_hi = tlo + (thi - tlo) * (b + 1) / tbins;
    s.rms = x.rms();
    s.mean = x.mean();
    s.order2_amplitude = x.order2();
    s.samples = x.n;
    out.time_bins.push_back(s);
  }
  for (int k = 0; k < 2; ++k) {
    const Bin& x = dir[static_cast<std::size_t>(k)];
    if (x.n == 0) continue;
    out.directions.push_back({k == 0 ? 1 : -1, x.n, x.rms(), x.mean()});
  }
  // Whiteness: autocorrelation of the mean-removed residual.
  if (lag_n[0] > 2 * kWhitenessLags) {
    const double mean = lead_sum[0] / static_cast<double>(lag_n[0]);
    const double c0 = lag_sum[0] / static_cast<double>(lag_n[0]) - mean * mean;
    out.whiteness.lags = kWhitenessLags;
    out.whiteness.samples = lag_n[0];
    out.whiteness.band = 2.58 / std::sqrt(static_cast<double>(lag_n[0]));
    for (int k = 1; k <= kWhitenessLags; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      if (lag_n[kk] == 0 || !(c0 > 0.0)) continue;
      const double nk = static_cast<double>(lag_n[kk]);
      const double ck = lag_sum[kk] / nk - mean * (lead_sum[kk] + lagged_sum[kk]) / nk + mean * mean;
      const double rho = ck / c0;
      out.whiteness.max_abs = std::max(out.whiteness.max_abs, std::abs(rho));
      if (std::abs(rho) > out.whiteness.band) ++out.whiteness.outside;
    }
  }
  (void)fitted;
  return out;
}

}  // namespace resolver
