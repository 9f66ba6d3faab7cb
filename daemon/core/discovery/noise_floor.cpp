#include "daemon/core/discovery/noise_floor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "daemon/core/angles.h"
#include "daemon/core/running_stats.h"
#include "daemon/core/model/normal_equations.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kSaturatedOrder = 16;
constexpr int kSpeedBins = 6;
constexpr std::size_t kMinStretch = 10;
/// [s] Left out at the start of every standstill stretch: the converter and the shaft
/// still settle there. After an abrupt stop the R/D loop's error rings down as
/// e^(-zeta omega_n t) from ~omega / omega_n (0.06 rad from 600 r/min at p_r = 3 and
/// omega_n = 3000 rad/s): in 2 ms of a 10 kHz log that ringing made a standstill floor
/// 11x the sensor's noise (3.1e-4 rad against 2.8e-5), and a log missing an effect was
/// called explained. 0.1 s is e^-7 of it for omega_n >= 100 rad/s at zeta = 0.7 (the
/// slow end of R/D converters) and covers a coupling's mechanical ring-down of tens of ms.
constexpr double kStandstillSettling = 0.1;
/// Samples per block by which a standstill stretch is judged settled beyond that: a
/// block's sample variance of white noise has a relative standard error
/// sqrt(2 / (B - 1)) = 0.14.
constexpr std::size_t kSettleBlock = 100;
/// A leading block whose mean square exceeds this multiple of the stretch's settled
/// variance is still settling. What rings on past it adds (ratio - 1) x tau / (2 T) of the
/// variance over a stretch of T s (tau the ringing's decay time): 1.5 keeps that to ~1 %
/// for tau = T / 10. White noise passes a block with chance ~0.9995 (3.5 of the standard
/// errors above), and a false skip only drops that block. A slow loop (a software
/// tracking observer of omega_n = 30 rad/s rings for ~0.3 s) or a lightly damped
/// coupling rings for longer than kStandstillSettling: such a stop made the position
/// error's floor 70x the sensor's (1.95e-3 rad against 2.8e-5).
constexpr double kSettleRatio = 1.5;

int nyquist_order(double omega_abs_max, double dt) {
  if (!(omega_abs_max > 0.0) || !(dt > 0.0)) return kSaturatedOrder;
  const int n = static_cast<int>(std::floor(0.9 * kPi / (omega_abs_max * dt)));
  return std::clamp(n, 2, kSaturatedOrder);
}

/// [1, sin n a, cos n a (n <= kSaturatedOrder)], then sin/cos of theta_m and 2 theta_m.
/// A bin's basis of order N is the first 1 + 2N entries and (mechanical) the last four.
constexpr int kFullBasis = 1 + 2 * kSaturatedOrder + 4;
using FullBasis = Eigen::Matrix<double, kFullBasis, 1>;

void full_basis(double a, double theta_m, FullBasis& x) {
  const double s1 = std::sin(a), c1 = std::cos(a);
  double sn = s1, cn = c1;
  int j = 0;
  x[j++] = 1.0;
  for (int n = 1; n <= kSaturatedOrder; ++n) {
    x[j++] = sn;
    x[j++] = cn;
    const double next = sn * c1 + cn * s1;
    cn = cn * c1 - sn * s1;
    sn = next;
  }
  x[j++] = std::sin(theta_m);
  x[j++] = std::cos(theta_m);
  x[j++] = std::sin(2.0 * theta_m);
  x[j++] = std::cos(2.0 * theta_m);
}

enum Sig { kRd, kSa, kSr, kD, kQ, kSigCount };

bool has_sig(const FitRow& r, int s) {
  if (s == kRd) return r.has(FitRow::kHasRd);
  if (s == kSa || s == kSr) return r.has(FitRow::kHasSc);
  return r.has(FitRow::kHasCur);
}
double value(const FitRow& r, int s) {
  switch (s) {
    case kRd: return r.y_rd;
    case kSa: return r.y_sa;
    case kSr: return r.y_sr;
    case kD: return r.y_d;
    default: return r.y_q;
  }
}

/// Second-difference floor of each signal (NaN where not estimable): per speed bin,
/// the second differences of each signal regressed on the second differences of its
/// angle harmonics up to what the bin's speed leaves below Nyquist (smooth structure
/// out), pooled over the bins. One pass over the rows; each row's basis (of theta for
/// the resolver's signals, theta_e for the currents) is computed once and shared by
/// every signal and the row's three triplets.
std::vector<double> second_difference_floors(std::span<const FitRow> rows, double dt, bool reference) {
  double wmax = 0.0;
  for (const FitRow& r : rows) {
    if (r.fitted()) wmax = std::max(wmax, std::abs(r.sig.omega));
  }
  std::vector<double> sum(kSigCount, 0.0), dof(kSigCount, 0.0);
  if (!(wmax > 0.0)) return std::vector<double>(kSigCount, kNaN);
  auto bin_of = [&](const FitRow& r) {
    return std::clamp(static_cast<int>(std::abs(r.sig.omega) / wmax * kSpeedBins), 0, kSpeedBins - 1);
  };
  const double e_per_r = rows.empty() ? 1.0 : static_cast<double>(rows.front().sig.p) / rows.front().sig.p_r;
  // Per bin and signal: the basis order, its width and the normal equations.
  struct Cell {
    int order = 0;
    int k = 0;
    bool mech = false;
    std::optional<NormalEquations> ne;
  };
  std::vector<Cell> cells(static_cast<std::size_t>(kSpeedBins) * kSigCount);
  auto cell = [&](int b, int s) -> Cell& {
    return cells[static_cast<std::size_t>(b) * kSigCount + static_cast<std::size_t>(s)];
  };
  for (int b = 0; b < kSpeedBins; ++b) {
    const double bin_wmax = wmax * (b + 1) / kSpeedBins;
    for (int s = 0; s < kSigCount; ++s) {
      const bool electrical = s == kD || s == kQ;
      Cell& c = cell(b, s);
      c.order = nyquist_order(bin_wmax * (electrical ? e_per_r : 1.0), dt);
      c.mech = reference && !electrical;
      c.k = 1 + 2 * c.order + (c.mech ? 4 : 0);
      c.ne.emplace(c.k);
    }
  }
  // Rolling bases of rows i-1, i, i+1 (index 0: theta, 1: theta_e).
  std::array<std::array<FullBasis, 3>, 2> basis;
  std::array<std::size_t, 3> basis_row{~std::size_t{0}, ~std::size_t{0}, ~std::size_t{0}};
  auto basis_of = [&](std::size_t row, int slot) {
    if (basis_row[static_cast<std::size_t>(slot)] != row) {
      const FitRow& r = rows[row];
      full_basis(r.sig.theta, r.sig.theta_m, basis[0][static_cast<std::size_t>(slot)]);
      full_basis(r.sig.theta_e, r.sig.theta_m, basis[1][static_cast<std::size_t>(slot)]);
      basis_row[static_cast<std::size_t>(slot)] = row;
    }
  };
  Eigen::VectorXd x;
  for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
    const FitRow& a = rows[i - 1];
    const FitRow& m = rows[i];
    const FitRow& c = rows[i + 1];
    if (!a.fitted() || !m.fitted() || !c.fitted()) continue;
    const int b = bin_of(m);
    if (bin_of(a) != b || bin_of(c) != b) continue;
    if (c.sig.t - a.sig.t > 3.0 * dt) continue;  // consecutive samples only
    // Slots by row index mod 3: each row's basis is computed once while it is in the triplet.
    const int sa = static_cast<int>((i - 1) % 3), sm = static_cast<int>(i % 3), sc = static_cast<int>((i + 1) % 3);
    basis_of(i - 1, sa);
    basis_of(i, sm);
    basis_of(i + 1, sc);
    for (int s = 0; s < kSigCount; ++s) {
      if (!has_sig(a, s) || !has_sig(m, s) || !has_sig(c, s)) continue;
      Cell& cl = cell(b, s);
      const auto& bs = basis[(s == kD || s == kQ) ? 1 : 0];
      const FullBasis d = bs[static_cast<std::size_t>(sc)] - 2.0 * bs[static_cast<std::size_t>(sm)] +
                          bs[static_cast<std::size_t>(sa)];
      x.resize(cl.k);
      x.head(1 + 2 * cl.order) = d.head(1 + 2 * cl.order);
      if (cl.mech) x.tail(4) = d.tail(4);
      cl.ne->add(x, value(c, s) - 2.0 * value(m, s) + value(a, s));
    }
  }
  for (int b = 0; b < kSpeedBins; ++b) {
    for (int s = 0; s < kSigCount; ++s) {
      Cell& cl = cell(b, s);
      NormalEquations& ne = *cl.ne;
      if (ne.n() < 4 * static_cast<std::int64_t>(cl.k)) continue;
      const Eigen::VectorXd coef = ne.m().completeOrthogonalDecomposition().solve(ne.b());
      // The differenced constant column is zero: k - 1 effective columns.
      sum[static_cast<std::size_t>(s)] += ne.rss(coef);
      dof[static_cast<std::size_t>(s)] += 6.0 * static_cast<double>(ne.n() - (cl.k - 1));
    }
  }
  std::vector<double> out(kSigCount, kNaN);
  for (int s = 0; s < kSigCount; ++s) {
    if (dof[static_cast<std::size_t>(s)] > 0.0) out[static_cast<std::size_t>(s)] = std::sqrt(sum[static_cast<std::size_t>(s)] / dof[static_cast<std::size_t>(s)]);
  }
  return out;
}

/// Each signal's moments over rows [from, to), outliers left out.
std::array<RunningStats, kSigCount> moments(std::span<const FitRow> rows, std::size_t from, std::size_t to) {
  std::array<RunningStats, kSigCount> m{};
  for (std::size_t k = from; k < to; ++k) {
    if (rows[k].has(FitRow::kOutlier)) continue;
    for (int s = 0; s < kSigCount; ++s) {
      if (has_sig(rows[k], s)) m[static_cast<std::size_t>(s)].add(value(rows[k], s));
    }
  }
  return m;
}

/// Where standstill stretch [i, j) has settled: the first block of kSettleBlock rows in
/// which every signal's mean square about its mean over the stretch's second half is
/// within kSettleRatio x its variance there (the second half assumed settled; at most it
/// is kept). About that mean, not the block's own: a ringing slower than a block (a 20 Hz
/// coupling mode is 500 rows at 10 kHz) moves the block's mean. A stretch too short to
/// judge is taken from `i`.
std::size_t settled_start(std::span<const FitRow> rows, std::size_t i, std::size_t j) {
  if (j - i < 4 * kSettleBlock) return i;
  const std::size_t half = i + (j - i) / 2;
  const std::array<RunningStats, kSigCount> tail = moments(rows, half, j);
  for (std::size_t b = i; b + kSettleBlock <= half; b += kSettleBlock) {
    const std::array<RunningStats, kSigCount> block = moments(rows, b, b + kSettleBlock);
    bool settled = true;
    for (std::size_t s = 0; s < block.size(); ++s) {
      if (block[s].n < 2 || tail[s].n < 2) continue;
      const double off = block[s].mean - tail[s].mean;
      if (block[s].variance() + off * off > kSettleRatio * tail[s].variance()) settled = false;
    }
    if (settled) return b;
  }
  return half;
}

/// Pooled within-stretch standard deviation of standstill samples, per signal, each
/// stretch after its first kStandstillSettling seconds and what it took beyond that to
/// settle (settled_start).
std::vector<double> standstill_floors(std::span<const FitRow> rows, double sample_period, std::int64_t& samples) {
  const auto settling =
      sample_period > 0.0 ? static_cast<std::size_t>(std::ceil(kStandstillSettling / sample_period)) : std::size_t{0};
  std::vector<double> ss(kSigCount, 0.0);
  std::vector<std::int64_t> n(kSigCount, 0), stretches(kSigCount, 0);
  samples = 0;
  std::size_t i = 0;
  while (i < rows.size()) {
    auto still = [&](std::size_t k) { return !rows[k].has(FitRow::kMoving) && !rows[k].has(FitRow::kExcluded); };
    if (!still(i)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < rows.size() && still(j)) ++j;
    i = settled_start(rows, std::min(j, i + settling), j);
    if (j - i >= kMinStretch) {
      const std::array<RunningStats, kSigCount> m = moments(rows, i, j);
      for (std::size_t s = 0; s < m.size(); ++s) {
        if (m[s].n < 2) continue;
        ss[s] += m[s].m2;
        n[s] += m[s].n;
        ++stretches[s];
      }
      samples += static_cast<std::int64_t>(j - i);
    }
    i = j;
  }
  std::vector<double> out(kSigCount, kNaN);
  for (int s = 0; s < kSigCount; ++s) {
    const auto k = static_cast<std::size_t>(s);
    const std::int64_t dof = n[k] - stretches[k];
    if (n[k] >= kMinStandstillSamples && dof > 0) out[k] = std::sqrt(ss[k] / static_cast<double>(dof));
  }
  return out;
}

double pair(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) ? b : a;
  return std::sqrt(0.5 * (a * a + b * b));
}

FloorEstimate choose(double second, double standstill, double quantization, std::int64_t ss_samples,
                     bool use_standstill) {
  FloorEstimate f;
  f.second_difference = second;
  f.quantization = quantization;
  f.standstill_samples = ss_samples;
  f.standstill = std::isnan(standstill) ? kNaN : std::sqrt(standstill * standstill + quantization * quantization);
  // A signal that holds exactly still at rest (a quantizer on one code, no visible
  // noise) says nothing about the moving floor unless the quantum is known; when the
  // quantum found is far below the moving samples' own noise (a scope export's print
  // rounding hides the converter's LSB), the moving samples are the only evidence.
  // (Exactly still: below a thousandth of the moving noise, the rounding of the sums.)
  const bool silent_at_rest = standstill < 1e-3 * second && quantization < 0.25 * second;
  if (use_standstill && f.standstill > 0.0 && !silent_at_rest) {
    f.chosen = f.standstill;
    f.source = "standstill";
  } else if (second > 0.0) {
    f.chosen = second;
    f.source = "second_differences";
  } else {
    f.chosen = 0.0;
    f.source = "none";
  }
  return f;
}

}  // namespace

double channel_quantum(std::span<const double> values) {
  if (values.size() < 8) return 0.0;
  // The quantizer's step shows in the differences of consecutive samples: they are
  // whole multiples of it, so the smallest gap between distinct differences (or the
  // smallest non-zero difference) is one step. A continuous signal shows a tiny
  // gap. (Sorting the values themselves would find the sampling lattice when the
  // speed is commensurate with the sample rate, not the quantizer.)
  const std::size_t n = std::min<std::size_t>(values.size(), 20001);
  std::vector<double> d;
  d.reserve(n);
  double lo = values[0], hi = values[0];
  for (std::size_t i = 1; i < n; ++i) {
    double x = values[i] - values[i - 1];
    if (x > kPi) x -= kTwoPi;  // wrapped angles: a step across 0 is small
    if (x < -kPi) x += kTwoPi;
    d.push_back(x);
    lo = std::min(lo, values[i]);
    hi = std::max(hi, values[i]);
  }
  const double range = hi - lo;
  if (!(range > 0.0)) return 0.0;
  std::sort(d.begin(), d.end());
  const double tiny = 1e-12 * range;
  double q = std::numeric_limits<double>::infinity();
  // Distinct non-zero step sizes: with only one (a commanded angle, or a fine reference
  // at a speed commensurate with the sample rate steps by exactly the same amount every
  // sample) the step is the motion, not the quantizer, and the quantum is unknown.
  double first_size = 0.0;
  bool two_sizes = false;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double a = std::abs(d[i]);
    if (a > tiny) {
      q = std::min(q, a);
      if (first_size == 0.0) first_size = a;
      else if (std::abs(a - first_size) > tiny) two_sizes = true;
    }
    if (i > 0 && d[i] - d[i - 1] > tiny) q = std::min(q, d[i] - d[i - 1]);
  }
  if (!two_sizes) return 0.0;
  return std::isfinite(q) && q > 1e-9 * range ? q : 0.0;
}

FloorReport estimate_floors(std::span<const FitRow> rows, double sample_period, bool reference,
                            const ChannelQuanta& quanta, bool use_standstill) {
  const std::vector<double> sd = second_difference_floors(rows, sample_period, reference);
  std::int64_t ss_samples = 0;
  const std::vector<double> st = standstill_floors(rows, sample_period, ss_samples);
  // Quantization while moving: uniform, LSB^2/12 per quantized channel.
  const double q_rd = std::sqrt((quanta.rd * quanta.rd + quanta.ref * quanta.ref) / 12.0);
  const double q_sc = quanta.amplitude > 0.0 ? quanta.sincos / quanta.amplitude / std::sqrt(12.0) : 0.0;
  FloorReport out;
  out.rd = choose(sd[kRd], st[kRd], q_rd, ss_samples, use_standstill);
  out.sc = choose(pair(sd[kSa], sd[kSr]), pair(st[kSa], st[kSr]), q_sc, ss_samples, use_standstill);
  out.cur = choose(pair(sd[kD], sd[kQ]), pair(st[kD], st[kQ]), 0.0, ss_samples, use_standstill);
  return out;
}

}  // namespace resolver
