#include "daemon/core/discovery/model_discovery.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "daemon/core/angles.h"
#include "daemon/core/discovery/effect_signatures.h"
#include "daemon/core/effects/effect_catalog.h"
#include "daemon/core/estimation/dq_transform.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Share of the samples that must carry a signal before it is used [1].
constexpr double kSignalPresentShare = 0.9;
/// Highest order of the saturated Fourier fit behind the noise floor (and the
/// smoothed ideal angle); capped further by the Nyquist limit of each speed bin.
constexpr int kSaturatedOrder = 16;
/// Samples each side of the central difference giving the speed.
constexpr std::size_t kSpeedHalfSpan = 2;
/// Tracking-loop search: omega_n grid [rad/s] (log spaced), zeta assumed (bench default).
constexpr double kOmegaNMin = 100.0, kOmegaNMax = 1e5;
constexpr int kOmegaNGrid = 61;
constexpr double kAssumedZeta = 0.7;
/// A candidate that does not reach the floor still counts as "the missing effect"
/// when it removes at least this share of the residual power above the floor.
constexpr double kExcessExplainedShare = 0.8;

struct Row {
  double t = 0.0;
  double theta = 0.0;    // [rad] true resolver electrical angle (continuous)
  double theta_m = 0.0;  // [rad] true mechanical angle (reference only)
  double omega = 0.0;    // [rad/s]
  double eps = 0.0;      // [rad]
  double ys = 0.0, yc = 0.0;
  bool env = false;
  double theta_e = 0.0;           // [rad] true motor electrical angle (currents only)
  double i_al = 0.0, i_be = 0.0;  // [A] Clarke of the measured phase currents
  double id = 0.0, iq = 0.0;      // [A] Park at theta_e
  bool cur = false;
  int bin = 0;
};

struct Prepared {
  int p_r = 3, p = 3;
  bool reference = false;
  bool env = false;
  bool cur = false;
  std::vector<Row> rows;
  std::vector<double> bin_edges;  // size bins + 1 [rad/s]
  double floor_rd = 0.0, floor_env = 0.0, floor_i = 0.0;
  double i_d0 = 0.0, i_q0 = 0.0;  // [A] mean measured dq current
  double sample_period = 0.0;
  std::vector<std::string> notes;
};

int nyquist_order(double omega_abs_max, double dt) {
  if (!(omega_abs_max > 0.0) || !(dt > 0.0)) return kSaturatedOrder;
  const double step = omega_abs_max * dt;  // [rad] per sample
  const int n = static_cast<int>(std::floor(0.9 * kPi / step));
  return std::clamp(n, 2, kSaturatedOrder);
}

/// Normal equations M = sum x x', b = sum x y, y'y of a row stream. Rows are
/// buffered and added a block at a time: one matrix product per block is several
/// times faster than a rank-1 update per row, and the fits here see every row of
/// a log dozens of times.
class Gram {
 public:
  explicit Gram(int k)
      : m_(Eigen::MatrixXd::Zero(k, k)), b_(Eigen::VectorXd::Zero(k)), rows_(kBlock, k), y_(kBlock) {}
  void add(const Eigen::VectorXd& x, double y) {
    rows_.row(used_) = x.transpose();
    y_[used_] = y;
    yy_ += y * y;
    ++n_;
    if (++used_ == kBlock) flush();
  }
  /// Adds the buffered rows; call before reading m() and b().
  void flush() {
    if (used_ == 0) return;
    const auto block = rows_.topRows(used_);
    m_.noalias() += block.transpose() * block;
    b_.noalias() += block.transpose() * y_.head(used_);
    used_ = 0;
  }
  [[nodiscard]] const Eigen::MatrixXd& m() const { return m_; }
  [[nodiscard]] const Eigen::VectorXd& b() const { return b_; }
  [[nodiscard]] double yy() const { return yy_; }
  [[nodiscard]] std::int64_t n() const { return n_; }
  /// Residual sum of squares of coefficients c: y'y - 2 c'b + c'Mc (>= 0).
  [[nodiscard]] double rss(const Eigen::VectorXd& c) const {
    if (c.size() == 0) return yy_;
    return std::max(0.0, yy_ - 2.0 * c.dot(b_) + c.dot(m_ * c));
  }

 private:
  static constexpr int kBlock = 64;
  Eigen::MatrixXd m_;
  Eigen::VectorXd b_;
  Eigen::MatrixXd rows_;
  Eigen::VectorXd y_;
  int used_ = 0;
  double yy_ = 0.0;
  std::int64_t n_ = 0;
};

/// The fully flexible angle model of one bin: [1, sin n theta, cos n theta (n <= order)]
/// plus 1x/2x mechanical with a reference.
void saturated_basis(const Row& r, int order, bool mech, Eigen::VectorXd& x, bool electrical = false) {
  const double a = electrical ? r.theta_e : r.theta;
  // sin/cos of n a by rotation (one sincos per row; the error grows ~n ulp).
  const double s1 = std::sin(a), c1 = std::cos(a);
  double sn = s1, cn = c1;
  int j = 0;
  x[j++] = 1.0;
  for (int n = 1; n <= order; ++n) {
    x[j++] = sn;
    x[j++] = cn;
    const double next_s = sn * c1 + cn * s1;
    cn = cn * c1 - sn * s1;
    sn = next_s;
  }
  if (mech) {
    for (int n = 1; n <= 2; ++n) {
      x[j++] = std::sin(n * r.theta_m);
      x[j++] = std::cos(n * r.theta_m);
    }
  }
}

/// Noise floors of several signals on the same rows: residual of the saturated
/// angle model per speed bin, then second differences of consecutive samples,
/// which remove whatever smooth structure is left (a drift in time, a slow speed
/// change): for white noise of standard deviation sigma,
/// var(r[i+1] - 2 r[i] + r[i-1]) = 6 sigma^2. The signals share one basis matrix
/// per bin, so its Gram matrix is formed once for all of them.
/// `electrical`: the signals' harmonics are of theta_e (currents), not theta.
std::vector<double> noise_floors(const Prepared& prep, const std::vector<std::size_t>& idx_all,
                                 const std::vector<double (*)(const Row&)>& values, bool electrical = false) {
  const double speed_ratio = electrical ? static_cast<double>(prep.p) / static_cast<double>(prep.p_r) : 1.0;
  const int bins = static_cast<int>(prep.bin_edges.size()) - 1;
  const auto m = static_cast<Eigen::Index>(values.size());
  std::vector<double> sum(values.size(), 0.0);
  std::int64_t count = 0;
  for (int b = 0; b < bins; ++b) {
    std::vector<std::size_t> idx;
    double wmax = 0.0;
    for (std::size_t i : idx_all) {
      if (prep.rows[i].bin == b) {
        idx.push_back(i);
        wmax = std::max(wmax, speed_ratio * std::abs(prep.rows[i].omega));
      }
    }
    const int order = nyquist_order(wmax, prep.sample_period);
    const int k = 1 + 2 * order + (prep.reference ? 4 : 0);
    if (idx.size() < 4 * static_cast<std::size_t>(k)) continue;
    const auto n = static_cast<Eigen::Index>(idx.size());
    Eigen::MatrixXd x(n, k), y(n, m);
    Eigen::VectorXd row(k);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Row& r = prep.rows[idx[static_cast<std::size_t>(i)]];
      saturated_basis(r, order, prep.reference, row, electrical);
      x.row(i) = row.transpose();
      for (Eigen::Index j = 0; j < m; ++j) y(i, j) = values[static_cast<std::size_t>(j)](r);
    }
    const Eigen::MatrixXd gram = x.transpose() * x;
    const Eigen::MatrixXd coef = gram.completeOrthogonalDecomposition().solve(x.transpose() * y);
    const Eigen::MatrixXd res = y - x * coef;
    for (Eigen::Index i = 1; i + 1 < n; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      if (idx[iu + 1] - idx[iu - 1] != 2) continue;  // consecutive samples only
      for (Eigen::Index j = 0; j < m; ++j) {
        const double d = res(i + 1, j) - 2.0 * res(i, j) + res(i - 1, j);
        sum[static_cast<std::size_t>(j)] += d * d;
      }
      ++count;
    }
  }
  std::vector<double> out(values.size(), kNaN);
  if (count > 0) {
    for (std::size_t j = 0; j < out.size(); ++j) out[j] = std::sqrt(sum[j] / (6.0 * static_cast<double>(count)));
  }
  return out;
}

/// Without a reference: the ideal angle as a quadratic in time per window of at
/// least two revolutions and 200 samples, fitted jointly with the harmonics of the
/// R/D angle (angle_error_fourier.h's fit_error_smooth_angle, done per window so
/// long logs with speed changes work). Returns the smoothed angle per sample.
std::vector<double> smoothed_ideal_angle(const std::vector<double>& t, const std::vector<double>& phi_c,
                                         const std::vector<double>& phi_w, double dt) {
  const std::size_t n = t.size();
  std::vector<double> out(n);
  constexpr std::size_t kMinWindow = 200;
  std::size_t i0 = 0;
  while (i0 < n) {
    std::size_t i1 = i0 + 1;
    while (i1 < n && (i1 - i0 < kMinWindow || std::abs(phi_c[i1 - 1] - phi_c[i0]) < 2.0 * kTwoPi)) ++i1;
    if (n - i1 < kMinWindow) i1 = n;  // fold a short tail into this window
    const double ta = t[i0], tb = t[i1 - 1];
    const double mid = 0.5 * (ta + tb), half = std::max(0.5 * (tb - ta), 1e-12);
    const double wmax = std::abs(phi_c[i1 - 1] - phi_c[i0]) / std::max(tb - ta, 1e-12);
    const int order = std::min(8, nyquist_order(wmax, dt));
    const int k = 3 + 2 * order;
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k, k);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(k);
    Eigen::VectorXd x(k);
    auto fill = [&](std::size_t i) {
      const double tau = (t[i] - mid) / half;
      x[0] = 1.0;
      x[1] = tau;
      x[2] = tau * tau;
      for (int h = 1; h <= order; ++h) {
        x[1 + 2 * h] = std::sin(h * phi_w[i]);
        x[2 + 2 * h] = std::cos(h * phi_w[i]);
      }
    };
    const double base = phi_c[i0];
    for (std::size_t i = i0; i < i1; ++i) {
      fill(i);
      m.selfadjointView<Eigen::Lower>().rankUpdate(x);
      b += x * (phi_c[i] - base);
    }
    m = m.selfadjointView<Eigen::Lower>();
    const Eigen::VectorXd c = m.completeOrthogonalDecomposition().solve(b);
    for (std::size_t i = i0; i < i1; ++i) {
      const double tau = (t[i] - mid) / half;
      out[i] = base + c[0] + c[1] * tau + c[2] * tau * tau;
    }
    i0 = i1;
  }
  return out;
}

Prepared prepare(const DiscoveryInput& in, const DiscoveryOptions& opt) {
  Prepared p;
  p.p_r = in.p_r;
  p.p = in.p;
  if (in.p_r < 1 || in.p < 1) throw std::invalid_argument("pole pairs p_r and p must be >= 1");
  std::vector<const DiscoverySample*> s;
  std::size_t with_ref = 0, with_sc = 0, with_i = 0;
  for (const auto& x : in.samples) {
    if (!x.has_rd) continue;
    s.push_back(&x);
    with_ref += x.has_ref ? 1 : 0;
    with_sc += x.has_sincos ? 1 : 0;
    with_i += x.has_currents ? 1 : 0;
  }
  if (s.size() < 64) {
    throw std::invalid_argument("too few samples with an R/D angle (" + std::to_string(s.size()) +
                                "): the log has no resolver samples the default layout decodes");
  }
  const double share = static_cast<double>(s.size());
  p.reference = static_cast<double>(with_ref) >= kSignalPresentShare * share;
  const bool sincos = static_cast<double>(with_sc) >= kSignalPresentShare * share;
  if (p.reference) {
    std::vector<const DiscoverySample*> keep;
    for (auto* x : s) {
      if (x->has_ref) keep.push_back(x);
    }
    s.swap(keep);
  } else {
    p.notes.emplace_back("no reference angle: fitting against the speed-smoothed ideal angle (constant errors, "
                      "mounting offset and eccentricity are not identifiable)");
  }
  if (!sincos) p.notes.emplace_back("no sin/cos envelopes: only the R/D angle is fitted (k3 and alpha are not separable)");
  else if (!p.reference) p.notes.emplace_back("sin/cos envelopes present but not fitted without a reference angle");
  const bool currents = static_cast<double>(with_i) >= kSignalPresentShare * share;
  if (!currents) p.notes.emplace_back("no phase currents in the log: current-side effects are not evaluated");
  else if (!p.reference) p.notes.emplace_back("phase currents present but not fitted without a reference angle (dq needs the true theta_e)");

  const std::size_t n = s.size();
  std::vector<double> t(n), truth(n), mech(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) t[i] = s[i]->t;
  double dt_sum = 0.0;
  for (std::size_t i = 1; i < n; ++i) dt_sum += t[i] - t[i - 1];
  p.sample_period = dt_sum / static_cast<double>(n - 1);
  if (p.reference) {
    AngleUnwrapper un;
    for (std::size_t i = 0; i < n; ++i) {
      mech[i] = un.update(s[i]->theta_m_ref);
      truth[i] = in.p_r * mech[i];
    }
  } else {
    std::vector<double> phi_c(n), phi_w(n);
    AngleUnwrapper un;
    for (std::size_t i = 0; i < n; ++i) {
      phi_w[i] = s[i]->theta_rd;
      phi_c[i] = un.update(s[i]->theta_rd);
    }
    truth = smoothed_ideal_angle(t, phi_c, phi_w, p.sample_period);
  }
  if (std::abs(truth.back() - truth.front()) < 2.0 * kTwoPi) {
    throw std::invalid_argument("the log covers less than two resolver revolutions: nothing to fit");
  }
  double amp = 0.0;
  if (sincos && p.reference) {
    double ss = 0.0;
    std::size_t m = 0;
    for (auto* x : s) {
      if (x->has_sincos) {
        ss += x->sin * x->sin;
        ++m;
      }
    }
    // [counts] A from the sin channel alone (rms x sqrt 2): the cos channel carries
    // (1 + alpha), and an A between the two would leave a gain nuisance g ~ -alpha/2
    // whose product g alpha (second order) the linear model cannot represent.
    amp = std::sqrt(2.0 * ss / static_cast<double>(m));
    p.env = amp > 0.0;
  }
  p.rows.resize(n);
  double wlo = std::numeric_limits<double>::infinity(), whi = -wlo;
  for (std::size_t i = 0; i < n; ++i) {
    Row& r = p.rows[i];
    const std::size_t a = i >= kSpeedHalfSpan ? i - kSpeedHalfSpan : 0;
    const std::size_t b = std::min(n - 1, i + kSpeedHalfSpan);
    r.t = t[i];
    r.theta = truth[i];
    r.theta_m = mech[i];
    r.omega = t[b] > t[a] ? (truth[b] - truth[a]) / (t[b] - t[a]) : 0.0;
    r.eps = wrap_pi(truth[i] - s[i]->theta_rd);
    if (p.env && s[i]->has_sincos) {
      r.env = true;
      r.ys = s[i]->sin / amp - std::sin(r.theta);
      r.yc = s[i]->cos / amp - std::cos(r.theta);
    }
    if (currents && p.reference && s[i]->has_currents) {
      r.cur = true;
      r.theta_e = static_cast<double>(p.p) * mech[i];
      const ClarkeTransform ab(s[i]->i_a, s[i]->i_b, s[i]->i_c);
      const ParkTransform dq(ab.alpha, ab.beta, r.theta_e);
      r.i_al = ab.alpha;
      r.i_be = ab.beta;
      r.id = dq.d;
      r.iq = dq.q;
    }
    wlo = std::min(wlo, r.omega);
    whi = std::max(whi, r.omega);
  }
  const int bins = (whi - wlo) > 0.02 * std::max(std::abs(whi), std::abs(wlo)) ? std::max(1, opt.speed_bins) : 1;
  for (int b = 0; b <= bins; ++b) p.bin_edges.push_back(wlo + (whi - wlo) * b / bins);
  for (auto& r : p.rows) {
    r.bin = bins == 1 ? 0 : std::clamp(static_cast<int>((r.omega - wlo) / (whi - wlo) * bins), 0, bins - 1);
  }
  std::vector<std::size_t> all(n), env_idx, cur_idx;
  for (std::size_t i = 0; i < n; ++i) {
    all[i] = i;
    if (p.rows[i].env) env_idx.push_back(i);
    if (p.rows[i].cur) {
      cur_idx.push_back(i);
      p.i_d0 += p.rows[i].id;
      p.i_q0 += p.rows[i].iq;
    }
  }
  p.cur = !cur_idx.empty();
  if (p.cur) {
    p.i_d0 /= static_cast<double>(cur_idx.size());
    p.i_q0 /= static_cast<double>(cur_idx.size());
    const auto f = noise_floors(p, cur_idx, {[](const Row& r) { return r.id; }, [](const Row& r) { return r.iq; }}, true);
    const double fd = f[0], fq = f[1];
    p.floor_i = std::sqrt(0.5 * (fd * fd + fq * fq));
    if (!(p.floor_i > 0.0)) {
      p.cur = false;
      p.notes.emplace_back("phase currents present but their noise floor could not be estimated: not fitted");
    }
  }
  // The envelopes are present on (nearly) every row: one basis for the three signals then.
  if (p.env && env_idx.size() == all.size()) {
    const auto f = noise_floors(p, all, {[](const Row& r) { return r.eps; }, [](const Row& r) { return r.ys; },
                                         [](const Row& r) { return r.yc; }});
    p.floor_rd = f[0];
    p.floor_env = std::sqrt(0.5 * (f[1] * f[1] + f[2] * f[2]));
  } else {
    p.floor_rd = noise_floors(p, all, {[](const Row& r) { return r.eps; }})[0];
    if (p.env) {
      const auto f = noise_floors(p, env_idx, {[](const Row& r) { return r.ys; }, [](const Row& r) { return r.yc; }});
      p.floor_env = std::sqrt(0.5 * (f[0] * f[0] + f[1] * f[1]));
    }
  }
  if (!(p.floor_rd > 0.0)) throw std::invalid_argument("could not estimate the noise floor (too few samples per speed)");
  if (p.env && !(p.floor_env > 0.0)) p.env = false;
  return p;
}

// ---------------------------------------------------------------- fitting

struct Design {
  std::vector<const EffectSignature*> effects;  // linear ones
  bool tracking = false;
  bool const_nuisance = false;  // rd constant (no reference: the smoothed angle absorbs it)
  bool gain_nuisance = false;   // envelope amplitude
  bool current_nuisance = false;  // DC i_d, i_q (the operating point)
  std::vector<std::string> names;
  int k = 0;
};

Design make_design(const Prepared& p, std::span<const std::string> effects) {
  Design d;
  d.const_nuisance = !p.reference;
  d.gain_nuisance = p.env;
  if (d.const_nuisance) d.names.emplace_back("nuisance.rd_constant");
  if (d.gain_nuisance) d.names.emplace_back("nuisance.sincos_gain");
  d.current_nuisance = p.cur;
  if (d.current_nuisance) {
    d.names.emplace_back("nuisance.i_d");
    d.names.emplace_back("nuisance.i_q");
  }
  for (const auto& e : effects) {
    const EffectSignature* sig = find_signature(e);
    if (sig == nullptr) {
      std::string list;
      for (const auto& x : effect_signatures()) list += (list.empty() ? "" : ", ") + std::string(x.effect);
      std::string msg = "effect '" + e + "' ";
      msg += find_effect(e) != nullptr ? "is in the catalog but not fittable in this version" : "is not in the effect catalog";
      msg += "; fittable: " + list;
      throw std::invalid_argument(msg);
    }
    if (sig->needs_reference && !p.reference) {
      throw std::invalid_argument("effect '" + e + "' needs the reference angle, which this log does not have");
    }
    if (sig->current_side() && !p.cur) {
      throw std::invalid_argument("effect '" + e + "' acts on the phase currents, which this log does not have");
    }
    if (sig->nonlinear) {
      d.tracking = true;
      continue;
    }
    if (std::find(d.effects.begin(), d.effects.end(), sig) != d.effects.end()) continue;
    d.effects.push_back(sig);
    for (auto name : sig->params) d.names.push_back(std::string(sig->effect) + "." + std::string(name));
  }
  d.k = static_cast<int>(d.names.size());
  return d;
}

struct Solved {
  bool ok = false;
  Eigen::VectorXd x;
  Eigen::VectorXd se;
  double rss_w = 0.0;
  double rss_rd = 0.0, rss_env = 0.0, rss_i = 0.0;
  std::int64_t n_rd = 0, n_env = 0, n_i = 0;
  double omega_n = 0.0, omega_n_se = kNaN;
  std::vector<double> resid_rd;
  std::vector<double> resid_d, resid_q;  // [A] per row; 0 where the row has no currents
};

/// Regressor rows of one sample, one entry per column.
struct RowRegressors {
  Eigen::VectorXd rd, s, c, d, q;
  explicit RowRegressors(int k) : rd(k), s(k), c(k), d(k), q(k) {}
};

/// Regressor rows for one sample: rd, s, c, d, q each of length k.
void fill_rows(const Prepared& p, const Design& d, const Row& r, double omega_n, double alpha_hat, RowRegressors& x) {
  x.rd.setZero();
  x.s.setZero();
  x.c.setZero();
  x.d.setZero();
  x.q.setZero();
  int j = 0;
  if (d.const_nuisance) x.rd[j++] = 1.0;
  if (d.gain_nuisance) {
    x.s[j] = std::sin(r.theta);
    x.c[j] = std::cos(r.theta);
    ++j;
  }
  if (d.current_nuisance) {
    x.d[j++] = 1.0;
    x.q[j++] = 1.0;
  }
  SignatureContext ctx{r.theta, r.theta_m, r.omega, p.p_r, p.p, omega_n, kAssumedZeta, alpha_hat,
                       r.theta_e, p.i_d0, p.i_q0};
  double b0[4], b1[4], b2[4];
  for (const auto* e : d.effects) {
    if (e->current_side()) {
      e->regress_dq(ctx, b0, b1);
      for (std::size_t i = 0; i < e->params.size(); ++i, ++j) {
        x.d[j] = b0[i];
        x.q[j] = b1[i];
      }
      continue;
    }
    e->regress(ctx, b0, b1, b2);
    for (std::size_t i = 0; i < e->params.size(); ++i, ++j) {
      x.rd[j] = b0[i];
      x.s[j] = b1[i];
      x.c[j] = b2[i];
    }
  }
}

Solved solve_linear(const Prepared& p, const Design& d, double omega_n, bool keep_residual, double alpha_hat) {
  Solved out;
  out.omega_n = omega_n;
  const int k = d.k;
  const double wr = 1.0 / p.floor_rd, we = p.env ? 1.0 / p.floor_env : 0.0, wi = p.cur ? 1.0 / p.floor_i : 0.0;
  RowRegressors x(k);
  // Normal equations per signal, so each signal's RSS follows from them
  // (Gram::rss) without a second pass over the rows.
  Gram nr(k), ne(k), ni(k);
  for (const auto& r : p.rows) {
    fill_rows(p, d, r, omega_n, alpha_hat, x);
    nr.add(x.rd, r.eps);
    if (r.env) {
      ne.add(x.s, r.ys);
      ne.add(x.c, r.yc);
    }
    if (r.cur) {
      ni.add(x.d, r.id);
      ni.add(x.q, r.iq);
    }
  }
  nr.flush();
  ne.flush();
  ni.flush();
  Eigen::MatrixXd m = nr.m() * (wr * wr) + ne.m() * (we * we) + ni.m() * (wi * wi);
  const Eigen::VectorXd b = nr.b() * (wr * wr) + ne.b() * (we * we) + ni.b() * (wi * wi);
  Eigen::VectorXd coef = Eigen::VectorXd::Zero(k);
  Eigen::MatrixXd minv = Eigen::MatrixXd::Zero(k, k);
  if (k > 0) {
    // Scale columns to unit diagonal so the rank test is about collinearity, not units.
    Eigen::VectorXd dg = m.diagonal().cwiseMax(1e-300).cwiseSqrt();
    const Eigen::MatrixXd ms = dg.cwiseInverse().asDiagonal() * m * dg.cwiseInverse().asDiagonal();
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(ms);
    cod.setThreshold(1e-9);
    if (cod.rank() < k) return out;  // not separable with the signals present
    coef = dg.cwiseInverse().asDiagonal() * cod.solve(dg.cwiseInverse().asDiagonal() * b);
    minv = dg.cwiseInverse().asDiagonal() * cod.pseudoInverse() * dg.cwiseInverse().asDiagonal();
  }
  out.n_rd = nr.n();
  out.n_env = ne.n();
  out.n_i = ni.n();
  if (!keep_residual) {
    out.rss_rd = nr.rss(coef);
    out.rss_env = ne.rss(coef);
    out.rss_i = ni.rss(coef);
  } else {
    // The residual per row is wanted (breakdowns, plots): a second pass, exact.
    out.resid_rd.reserve(p.rows.size());
    if (p.cur) {
      out.resid_d.reserve(p.rows.size());
      out.resid_q.reserve(p.rows.size());
    }
    for (const auto& r : p.rows) {
      fill_rows(p, d, r, omega_n, alpha_hat, x);
      const double er = r.eps - x.rd.dot(coef);
      out.rss_rd += er * er;
      out.resid_rd.push_back(er);
      if (r.env) {
        const double es = r.ys - x.s.dot(coef), ec = r.yc - x.c.dot(coef);
        out.rss_env += es * es + ec * ec;
      }
      const double ed = r.cur ? r.id - x.d.dot(coef) : 0.0, eq = r.cur ? r.iq - x.q.dot(coef) : 0.0;
      out.rss_i += ed * ed + eq * eq;
      if (p.cur) {
        out.resid_d.push_back(ed);
        out.resid_q.push_back(eq);
      }
    }
  }
  out.rss_w = out.rss_rd * wr * wr + out.rss_env * we * we + out.rss_i * wi * wi;
  const double dof = static_cast<double>(out.n_rd + out.n_env + out.n_i - k - (d.tracking ? 1 : 0));
  const double s2 = out.rss_w / std::max(dof, 1.0);
  out.x = coef;
  out.se = (s2 * minv.diagonal()).cwiseMax(0.0).cwiseSqrt();
  out.ok = true;
  return out;
}

/// Index of amplitude_imbalance.alpha in the design, or -1.
int alpha_column(const Design& d) {
  for (int j = 0; j < d.k; ++j) {
    if (d.names[j] == "amplitude_imbalance.alpha") return j;
  }
  return -1;
}

/// `alpha_hint`: alpha_hat from an earlier fit of the same log (a candidate's fit
/// reuses the model's); NaN = run the preliminary pass.
Solved solve(const Prepared& p, const Design& d, bool keep_residual, double alpha_hint = kNaN) {
  // Preliminary linear pass for alpha_hat (see SignatureContext::alpha_hat).
  double alpha_hat = std::isfinite(alpha_hint) ? alpha_hint : 0.0;
  if (const int ja = alpha_column(d); ja >= 0 && !std::isfinite(alpha_hint)) {
    const Solved pre = solve_linear(p, d, 0.0, false, 0.0);
    if (pre.ok) alpha_hat = pre.x[ja];
  }
  if (!d.tracking) return solve_linear(p, d, 0.0, keep_residual, alpha_hat);
  // omega_n: log grid, then golden-section refinement in log omega_n.
  auto cost = [&](double lw) {
    const Solved s = solve_linear(p, d, std::exp(lw), false, alpha_hat);
    return s.ok ? s.rss_w : std::numeric_limits<double>::infinity();
  };
  const double l0 = std::log(kOmegaNMin), l1 = std::log(kOmegaNMax);
  double best_l = l0, best_c = std::numeric_limits<double>::infinity();
  const double step = (l1 - l0) / (kOmegaNGrid - 1);
  for (int i = 0; i < kOmegaNGrid; ++i) {
    const double l = l0 + step * i;
    const double c = cost(l);
    if (c < best_c) {
      best_c = c;
      best_l = l;
    }
  }
  double a = best_l - step, b = best_l + step;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c1 = b - g * (b - a), c2 = a + g * (b - a);
  double f1 = cost(c1), f2 = cost(c2);
  for (int it = 0; it < 40; ++it) {
    if (f1 < f2) {
      b = c2;
      c2 = c1;
      f2 = f1;
      c1 = b - g * (b - a);
      f1 = cost(c1);
    } else {
      a = c1;
      c1 = c2;
      f1 = f2;
      c2 = a + g * (b - a);
      f2 = cost(c2);
    }
  }
  const double lopt = 0.5 * (a + b);
  Solved out = solve_linear(p, d, std::exp(lopt), keep_residual, alpha_hat);
  if (!out.ok) return out;
  // Standard error from the curvature of the weighted RSS (chi^2 / s^2 rises by 1 at 1 sigma).
  const double h = 0.01;
  const double curv = (cost(lopt + h) - 2.0 * out.rss_w + cost(lopt - h)) / (h * h);
  const double dof = static_cast<double>(out.n_rd + out.n_env + out.n_i - d.k - 1);
  const double s2 = out.rss_w / std::max(dof, 1.0);
  out.omega_n_se = curv > 0.0 ? std::exp(lopt) * std::sqrt(2.0 * s2 / curv) : kNaN;
  return out;
}

double bic(const Solved& s, const Design& d) {
  const double n = static_cast<double>(s.n_rd + s.n_env + s.n_i);
  const double k = static_cast<double>(d.k + (d.tracking ? 1 : 0));
  return n * std::log(s.rss_w / n) + k * std::log(n);
}

double rms(double rss, std::int64_t n) { return n > 0 ? std::sqrt(rss / static_cast<double>(n)) : 0.0; }

/// `electrical`: orders of theta_e over the rows with currents (else of theta over all rows).
std::vector<HarmonicResidual> harmonic_breakdown(const Prepared& p, const std::vector<double>& r, int max_order,
                                                 bool electrical = false) {
  const int k = 1 + 2 * max_order;
  Gram g(k);
  Eigen::VectorXd x(k);
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (electrical && !p.rows[i].cur) continue;
    saturated_basis(p.rows[i], max_order, false, x, electrical);
    g.add(x, r[i]);
  }
  g.flush();
  const Eigen::VectorXd c = g.m().completeOrthogonalDecomposition().solve(g.b());
  std::vector<HarmonicResidual> out;
  out.push_back({0, std::abs(c[0]), c[0] >= 0.0 ? 0.0 : kPi});
  for (int n = 1; n <= max_order; ++n) {
    const double a = c[2 * Eigen::Index{n} - 1], bb = c[2 * Eigen::Index{n}];
    out.push_back({n, std::hypot(a, bb), std::atan2(bb, a)});
  }
  return out;
}

std::vector<SpeedBinResidual> speed_breakdown(const Prepared& p, const std::vector<double>& r) {
  const int bins = static_cast<int>(p.bin_edges.size()) - 1;
  std::vector<SpeedBinResidual> out;
  for (int b = 0; b < bins; ++b) {
    SpeedBinResidual s;
    s.omega_lo = p.bin_edges[b];
    s.omega_hi = p.bin_edges[b + 1];
    s.rpm_mid = 0.5 * (s.omega_lo + s.omega_hi) / p.p_r * 60.0 / kTwoPi;
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double ss = 0.0;
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (p.rows[i].bin != b) continue;
      ++s.samples;
      ss += r[i] * r[i];
      const Eigen::Vector3d x(1.0, std::sin(2.0 * p.rows[i].theta), std::cos(2.0 * p.rows[i].theta));
      m += x * x.transpose();
      v += x * r[i];
    }
    if (s.samples < 16) continue;
    s.rms = std::sqrt(ss / static_cast<double>(s.samples));
    const Eigen::Vector3d c = m.completeOrthogonalDecomposition().solve(v);
    s.order2_amplitude = std::hypot(c[1], c[2]);
    out.push_back(s);
  }
  return out;
}

std::vector<TimeBinResidual> time_breakdown(const Prepared& p, const std::vector<double>& r, int bins) {
  std::vector<TimeBinResidual> out;
  if (r.empty() || bins < 1) return out;
  const double t0 = p.rows.front().t, t1 = p.rows.back().t;
  const double span = std::max(t1 - t0, 1e-12);
  std::vector<Eigen::Matrix3d> m(bins, Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> v(bins, Eigen::Vector3d::Zero());
  std::vector<double> ss(bins, 0.0);
  out.resize(bins);
  for (std::size_t i = 0; i < r.size(); ++i) {
    const int b = std::clamp(static_cast<int>((p.rows[i].t - t0) / span * bins), 0, bins - 1);
    const Eigen::Vector3d x(1.0, std::sin(2.0 * p.rows[i].theta), std::cos(2.0 * p.rows[i].theta));
    m[b] += x * x.transpose();
    v[b] += x * r[i];
    ss[b] += r[i] * r[i];
    ++out[b].samples;
  }
  for (int b = 0; b < bins; ++b) {
    out[b].t_lo = span * b / bins;
    out[b].t_hi = span * (b + 1) / bins;
    if (out[b].samples < 16) continue;
    out[b].rms = std::sqrt(ss[b] / static_cast<double>(out[b].samples));
    const Eigen::Vector3d c = m[b].completeOrthogonalDecomposition().solve(v[b]);
    out[b].order2_amplitude = std::hypot(c[1], c[2]);
  }
  std::erase_if(out, [](const TimeBinResidual& x) { return x.samples < 16; });
  return out;
}

/// Whether the log spans speeds far enough apart for the tracking loop's filtering
/// to change visibly: the fastest 5 % of samples at least 1.5x the slowest 5 %.
bool two_speeds(const Prepared& p) {
  std::vector<double> w;
  w.reserve(p.rows.size());
  for (const auto& r : p.rows) w.push_back(std::abs(r.omega));
  if (w.size() < 20) return false;
  const std::size_t lo = w.size() / 20, hi = w.size() - 1 - w.size() / 20;
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(lo), w.end());
  const double slow = w[lo];
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(hi), w.end());
  return w[hi] >= 1.5 * slow;
}

bool signals_explained(const Prepared& p, const Solved& s, double ratio) {
  if (rms(s.rss_rd, s.n_rd) > ratio * p.floor_rd) return false;
  if (p.env && rms(s.rss_env, s.n_env) > ratio * p.floor_env) return false;
  if (p.cur && rms(s.rss_i, s.n_i) > ratio * p.floor_i) return false;
  return true;
}

std::vector<ParamValue> params_of(const Design& d, const Solved& s, bool with_nuisance) {
  std::vector<ParamValue> out;
  for (int j = 0; j < d.k; ++j) {
    if (!with_nuisance && d.names[j].rfind("nuisance.", 0) == 0) continue;
    out.push_back({d.names[j], s.x[j], s.se[j]});
  }
  if (d.tracking) out.push_back({"tracking_loop.omega_n", s.omega_n, s.omega_n_se});
  return out;
}

ResidualSeries residual_series(const Prepared& p, const Solved& s, int points) {
  ResidualSeries out;
  const std::size_t n = p.rows.size();
  const std::size_t step = std::max<std::size_t>(1, n / static_cast<std::size_t>(points));
  const double e_per_r = static_cast<double>(p.p) / static_cast<double>(p.p_r);
  for (std::size_t i = 0; i < n; i += step) {
    const Row& r = p.rows[i];
    out.t.push_back(r.t);
    out.theta.push_back(wrap_2pi(r.theta));
    out.rpm.push_back(r.omega / p.p_r * 60.0 / kTwoPi);
    out.eps_measured.push_back(r.eps);
    const double model = r.eps - s.resid_rd[i];
    out.eps_model.push_back(model);
    if (!r.cur) continue;
    // The drive's angle: the R/D angle theta - eps, raw or corrected by the model's eps.
    const ParkTransform raw(r.i_al, r.i_be, e_per_r * (r.theta - r.eps));
    const ParkTransform comp(r.i_al, r.i_be, e_per_r * (r.theta - r.eps + model));
    out.i_d_raw.push_back(raw.d);
    out.i_q_raw.push_back(raw.q);
    out.i_d_comp.push_back(comp.d);
    out.i_q_comp.push_back(comp.q);
    out.i_d_ref.push_back(r.id);
    out.i_q_ref.push_back(r.iq);
  }
  return out;
}

ModelFit fit_prepared(const Prepared& p, std::span<const std::string> effects, const DiscoveryOptions& opt,
                      Design& d, Solved& s) {
  d = make_design(p, effects);
  s = solve(p, d, true);
  if (!s.ok) {
    throw std::invalid_argument("the model's effects are not separable with the signals in this log "
                                "(e.g. harmonics and amplitude_imbalance both land on 2 theta without sin/cos)");
  }
  const Solved raw = solve_linear(p, make_design(p, {}), 0.0, false, 0.0);
  ModelFit f;
  for (const auto& e : effects) {
    if (std::find(f.effects.begin(), f.effects.end(), e) == f.effects.end()) f.effects.push_back(e);
  }
  f.params = params_of(d, s, false);
  f.signals.push_back({"position_error", rms(s.rss_rd, s.n_rd), p.floor_rd, rms(raw.rss_rd, raw.n_rd), s.n_rd});
  if (p.env) f.signals.push_back({"sin_cos", rms(s.rss_env, s.n_env), p.floor_env, rms(raw.rss_env, raw.n_env), s.n_env});
  if (p.cur) f.signals.push_back({"i_dq", rms(s.rss_i, s.n_i), p.floor_i, rms(raw.rss_i, raw.n_i), s.n_i});
  f.residual_rms_rad = rms(s.rss_rd, s.n_rd);
  f.noise_floor_rad = p.floor_rd;
  f.harmonics = harmonic_breakdown(p, s.resid_rd, std::max(0, opt.max_report_order));
  f.speed_bins = speed_breakdown(p, s.resid_rd);
  f.time_bins = time_breakdown(p, s.resid_rd, opt.time_bins);
  if (p.cur) {
    f.harmonics_id = harmonic_breakdown(p, s.resid_d, std::max(0, opt.max_report_order), true);
    f.harmonics_iq = harmonic_breakdown(p, s.resid_q, std::max(0, opt.max_report_order), true);
  }
  if (opt.series_points > 0) f.series = residual_series(p, s, opt.series_points);
  f.bic = bic(s, d);
  f.rows = s.n_rd + s.n_env + s.n_i;
  f.parameters = d.k + (d.tracking ? 1 : 0);
  f.reference = p.reference;
  f.sincos_used = p.env;
  f.currents_used = p.cur;
  f.explained = signals_explained(p, s, opt.explained_ratio);
  f.notes = p.notes;
  if (d.tracking) f.notes.emplace_back("tracking_loop: zeta assumed 0.7, omega_n searched on [100, 1e5] rad/s");
  return f;
}

std::string fmt_num(double v, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::vector<std::string> describe_failure(const Prepared& p, const ModelFit& f, double ratio) {
  std::vector<std::string> out;
  for (const auto& s : f.signals) {
    if (s.rms <= ratio * s.floor) continue;
    const std::string unit = s.signal == "position_error" ? " rad (" + fmt_num(rad_to_arcmin(s.rms)) + " arcmin)"
                             : s.signal == "i_dq"         ? " A"
                                                          : " of the amplitude";
    out.emplace_back(s.signal + ": residual " + fmt_num(s.rms) + unit +
                  " is " + fmt_num(s.rms / s.floor, "%.1f") + "x the noise floor " + fmt_num(s.floor));
  }
  if (out.empty()) return out;
  // Which harmonics: those above a fifth of the floor, largest first.
  std::vector<HarmonicResidual> h = f.harmonics;
  std::sort(h.begin(), h.end(), [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  std::string hs;
  for (const auto& x : h) {
    if (x.amplitude < 0.2 * p.floor_rd || hs.size() > 200) break;
    const double deg = x.phase * 180.0 / kPi;
    std::string phase;
    if (x.order > 0) {
      const double a = std::fmod(std::abs(deg), 180.0);
      phase = a < 20.0 || a > 160.0 ? " (in phase with sin)" : (std::abs(a - 90.0) < 20.0 ? " (in phase with cos)" : " (phase " + fmt_num(deg, "%.0f") + " deg)");
    }
    hs += (hs.empty() ? "" : ", ") + (x.order == 0 ? std::string("constant") : std::to_string(x.order) + " theta") +
          " " + fmt_num(x.amplitude) + " rad" + phase;
  }
  // Only when the position error itself fails: below the floor its harmonics are
  // the quantization pattern, not a lead.
  const bool position_fails = f.signals[0].rms > ratio * f.signals[0].floor;
  if (position_fails && !hs.empty()) out.emplace_back("position-error residual by harmonic: " + hs);
  else if (position_fails)
    out.emplace_back("position-error residual is not locked to the angle (no harmonic of theta above a fifth of the floor): it changes over time");
  // The dq currents, by order of theta_e: which ripple the current sensors or the inverter leave.
  for (const auto& s : f.signals) {
    if (s.signal != "i_dq" || s.rms <= ratio * s.floor) continue;
    std::string cs;
    for (std::size_t n = 1; n < f.harmonics_id.size() && n < f.harmonics_iq.size(); ++n) {
      const double ad = f.harmonics_id[n].amplitude, aq = f.harmonics_iq[n].amplitude;
      if (std::max(ad, aq) < 0.2 * p.floor_i) continue;
      cs += (cs.empty() ? "" : ", ") + std::to_string(n) + " theta_e: i_d " + fmt_num(ad) + " A, i_q " + fmt_num(aq) + " A";
    }
    out.emplace_back(cs.empty() ? "i_dq residual is not locked to theta_e (no harmonic above a fifth of the floor)"
                             : "i_dq residual by harmonic of theta_e: " + cs);
  }
  // Over time: the catalog's effects are fixed in time, so a residual that grows or
  // shrinks from window to window (at whatever speed) is something the catalog lacks.
  if (f.time_bins.size() > 1) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    std::string ts;
    for (const auto& b : f.time_bins) {
      lo = std::min(lo, b.rms);
      hi = std::max(hi, b.rms);
      ts += (ts.empty() ? "" : ", ") + fmt_num(b.t_lo, "%.3g") + "-" + fmt_num(b.t_hi, "%.3g") + " s: " +
            fmt_num(b.rms / p.floor_rd, "%.1f") + "x floor (2 theta " + fmt_num(b.order2_amplitude) + " rad)";
    }
    if (hi > ratio * p.floor_rd && hi > 2.0 * lo) {
      out.emplace_back("the position-error residual changes over time (" + ts +
                    "): no catalog effect depends on time (a drift, e.g. with temperature, is outside the catalog)");
    }
  }
  if (f.speed_bins.size() > 1) {
    std::string bs;
    for (const auto& b : f.speed_bins) {
      bs += (bs.empty() ? "" : ", ") + fmt_num(b.rpm_mid, "%.0f") + " r/min: " + fmt_num(b.rms / p.floor_rd, "%.1f") + "x floor";
    }
    out.emplace_back("by speed: " + bs);
  }
  return out;
}

}  // namespace

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::kExplained: return "explained";
    case Verdict::kMissingEffect: return "missing_effect";
    case Verdict::kUnexplained: return "unexplained";
  }
  return "?";
}

std::span<const std::string_view> fittable_effects() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> v;
    for (const auto& s : effect_signatures()) v.push_back(s.effect);
    return v;
  }();
  return names;
}

ModelFit fit_model(const DiscoveryInput& input, std::span<const std::string> effects, const DiscoveryOptions& options) {
  const Prepared p = prepare(input, options);
  Design d;
  Solved s;
  return fit_prepared(p, effects, options, d, s);
}

Explanation explain_model(const DiscoveryInput& input, std::span<const std::string> effects,
                          const DiscoveryOptions& options) {
  const Prepared p = prepare(input, options);
  if (options.progress) options.progress(0.05);
  Explanation ex;
  Design d;
  Solved base;
  ex.fit = fit_prepared(p, effects, options, d, base);
  if (ex.fit.explained && !options.rank_when_explained) {
    ex.verdict = Verdict::kExplained;
    ex.summary = "explained: every signal's residual is within " + fmt_num(options.explained_ratio) +
                 "x its noise floor; no effect is needed (candidates not ranked).";
    return ex;
  }
  const double base_bic = ex.fit.bic;
  // Candidates linearise at the model's alpha (SignatureContext::alpha_hat): the
  // added effect moves alpha by far less than the O(alpha^3) the linearisation drops.
  const int ja = alpha_column(d);
  const double alpha_hint = ja >= 0 ? base.x[ja] : kNaN;
  const auto sigs = effect_signatures();
  std::vector<double> weighted_rss_after;  // per candidate, for the excess rule below
  std::size_t done = 0;
  for (const auto& sig : sigs) {
    ++done;
    if (options.progress) options.progress(0.05 + 0.95 * static_cast<double>(done) / static_cast<double>(sigs.size()));
    const std::string name(sig.effect);
    if (std::find(ex.fit.effects.begin(), ex.fit.effects.end(), name) != ex.fit.effects.end()) continue;
    if (sig.needs_reference && !p.reference) {
      ex.not_evaluated.emplace_back(name + ": needs the reference angle");
      continue;
    }
    if (sig.current_side() && !p.cur) {
      ex.not_evaluated.emplace_back(name + ": needs the phase currents");
      continue;
    }
    if (sig.nonlinear && !two_speeds(p)) {
      // H(j k omega) at one speed is a fixed gain and phase per harmonic: it cannot be
      // told from the other effects' amplitudes, and the omega_n search is the costly part.
      ex.not_evaluated.emplace_back(name + ": one speed in this log; the loop's filtering shows only over a speed change");
      continue;
    }
    std::vector<std::string> with(ex.fit.effects.begin(), ex.fit.effects.end());
    with.push_back(name);
    const Design dc = make_design(p, with);
    const Solved sc = solve(p, dc, false, alpha_hint);
    if (!sc.ok) {
      ex.not_evaluated.emplace_back(name + ": not separable from the model with the signals in this log" +
                                 (p.env ? std::string() : std::string(" (needs sin/cos with a reference)")));
      continue;
    }
    Candidate c;
    c.effect = name;
    c.residual_after_rad = rms(sc.rss_rd, sc.n_rd);
    c.sincos_residual_after = rms(sc.rss_env, sc.n_env);
    c.dq_residual_after = rms(sc.rss_i, sc.n_i);
    c.weighted_rss = sc.rss_w;
    c.score = bic(sc, dc);
    c.bic_drop = base_bic - c.score;
    c.proposed = c.bic_drop > options.proposal_bic_drop;
    c.reaches_floor = signals_explained(p, sc, options.explained_ratio);
    for (const auto& pv : params_of(dc, sc, false)) {
      if (pv.name.rfind(name + ".", 0) == 0) c.params.push_back(pv);
    }
    std::string vals;
    for (const auto& pv : c.params) vals += (vals.empty() ? "" : ", ") + pv.name.substr(name.size() + 1) + " = " + fmt_num(pv.value) + " +- " + fmt_num(pv.std_error, "%.2g");
    c.reason = std::string(sig.physics) + " (fit: " + vals + ").";
    ex.candidates.push_back(std::move(c));
  }
  for (const auto& e : effect_catalog()) {
    if (find_signature(e.name) != nullptr) continue;
    const std::string n(e.name);
    if (n == "quantization" || n == "noise") ex.not_evaluated.emplace_back(n + ": sets the noise floor, not a candidate");
    else ex.not_evaluated.emplace_back(n + ": no signature in this version");
  }
  std::sort(ex.candidates.begin(), ex.candidates.end(), [](const auto& a, const auto& b) { return a.score < b.score; });

  if (ex.fit.explained) {
    // Nothing to propose: a BIC gain below the floor's resolution is not a missing
    // effect (e.g. second-order terms between effects); the scores stay listed.
    for (auto& c : ex.candidates) c.proposed = false;
    ex.verdict = Verdict::kExplained;
    ex.summary = "explained: every signal's residual is within " + fmt_num(options.explained_ratio) +
                 "x its noise floor; no effect is needed.";
    return ex;
  }
  ex.where_it_fails = describe_failure(p, ex.fit, options.explained_ratio);
  const Candidate* best = ex.candidates.empty() || !ex.candidates.front().proposed ? nullptr : &ex.candidates.front();
  bool named = false;
  if (best != nullptr) {
    if (best->reaches_floor) {
      named = true;
    } else {
      // Share of the weighted residual power above the floor that the candidate removes
      // (each row's weight is 1/floor, so a row at the floor contributes 1).
      const double rows = static_cast<double>(base.n_rd + base.n_env + base.n_i);
      const double excess = base.rss_w - rows;
      const double after = best->weighted_rss - rows;
      named = excess > 0.0 && (excess - after) >= kExcessExplainedShare * excess;
    }
  }
  // Two effects missing at once: neither alone removes most of the excess, but a
  // pair of the proposed ones may reach the floor together (forward selection, one
  // step deeper; only the three best proposed candidates, so at most three fits).
  if (!named && best != nullptr) {
    std::vector<const Candidate*> top;
    for (const auto& c : ex.candidates) {
      if (c.proposed && top.size() < 3) top.push_back(&c);
    }
    for (std::size_t i = 0; i < top.size() && ex.missing_pair.empty(); ++i) {
      for (std::size_t j = i + 1; j < top.size() && ex.missing_pair.empty(); ++j) {
        std::vector<std::string> with(ex.fit.effects.begin(), ex.fit.effects.end());
        with.push_back(top[i]->effect);
        with.push_back(top[j]->effect);
        const Design dp = make_design(p, with);
        const Solved sp = solve(p, dp, false, alpha_hint);
        if (sp.ok && signals_explained(p, sp, options.explained_ratio)) {
          ex.missing_pair = {top[i]->effect, top[j]->effect};
        }
      }
    }
  }
  if (!ex.missing_pair.empty()) {
    ex.verdict = Verdict::kMissingEffect;
    ex.summary = "missing_effect: two effects are missing: " + ex.missing_pair[0] + " and " + ex.missing_pair[1] +
                 " together bring every signal to within " + fmt_num(options.explained_ratio) +
                 "x its noise floor (neither does alone); add " + best->effect + " first. " + best->reason;
  } else if (named) {
    ex.verdict = Verdict::kMissingEffect;
    // Say it on the signal the effect changes most (in units of its floor).
    struct Change {
      const char* what;
      double before, after, floor;
      const char* unit;
    };
    std::vector<Change> changes{{"position-error", ex.fit.residual_rms_rad, best->residual_after_rad, p.floor_rd, " rad"}};
    for (const auto& sr : ex.fit.signals) {
      if (sr.signal == "sin_cos") changes.push_back({"sin/cos", sr.rms, best->sincos_residual_after, sr.floor, " of the amplitude"});
      if (sr.signal == "i_dq") changes.push_back({"i_dq", sr.rms, best->dq_residual_after, sr.floor, " A"});
    }
    const Change& c = *std::max_element(changes.begin(), changes.end(), [](const Change& x, const Change& y) {
      return (x.before - x.after) / x.floor < (y.before - y.after) / y.floor;
    });
    ex.summary = "missing_effect: adding " + best->effect + " brings the " + c.what + " residual from " +
                 fmt_num(c.before) + " to " + fmt_num(c.after) + c.unit + " (floor " + fmt_num(c.floor) + "); " +
                 best->reason;
  } else {
    ex.verdict = Verdict::kUnexplained;
    ex.summary = "unexplained: no catalog effect brings the residual near the noise floor; the residual is described "
                 "above instead of naming an effect.";
  }
  return ex;
}

}  // namespace resolver
