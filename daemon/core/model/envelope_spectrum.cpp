#include "daemon/core/model/envelope_spectrum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include "daemon/core/angles.h"

namespace resolver {

namespace {

constexpr int kOrders = kGridPoints / 2;  // orders 0 .. kOrders - 1 are resolved

/// cos / sin (k phi_j) for every order and grid angle, computed once.
struct Table {
  std::array<std::array<double, kGridPoints>, kOrders> c{}, s{};
  Table() {
    for (int k = 0; k < kOrders; ++k) {
      for (int j = 0; j < kGridPoints; ++j) {
        const double a = 2.0 * std::numbers::pi * static_cast<double>(k) * j / kGridPoints;
        c[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)] = std::cos(a);
        s[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)] = std::sin(a);
      }
    }
  }
};

const Table& table() {
  static const Table t;
  return t;
}

double grid_angle(int j) { return 2.0 * std::numbers::pi * j / kGridPoints; }

using Samples = std::array<double, kGridPoints>;

/// The Fourier series of e and r tabulated on the grid (discrete transform: exact for
/// orders below kOrders), orders with a coefficient above `drop_below` kept.
EnvelopeSeries transform(const Samples& e, const Samples& r, double drop_below) {
  const Table& t = table();
  EnvelopeSeries out;
  for (int k = 0; k < kOrders; ++k) {
    const auto& ck = t.c[static_cast<std::size_t>(k)];
    const auto& sk = t.s[static_cast<std::size_t>(k)];
    double ec = 0.0, es = 0.0, rc = 0.0, rs = 0.0;
    for (std::size_t j = 0; j < kGridPoints; ++j) {
      ec += e[j] * ck[j];
      es += e[j] * sk[j];
      rc += r[j] * ck[j];
      rs += r[j] * sk[j];
    }
    const double w = (k == 0 ? 1.0 : 2.0) / kGridPoints;
    ec *= w;
    es *= w;
    rc *= w;
    rs *= w;
    if (std::abs(ec) + std::abs(es) + std::abs(rc) + std::abs(rs) <= drop_below) continue;
    out.k.push_back(k);
    out.e_cos.push_back(ec);
    out.e_sin.push_back(es);
    out.r_cos.push_back(rc);
    out.r_sin.push_back(rs);
  }
  return out;
}

}  // namespace

SinCos envelopes_through(std::span<const EnvelopeMember> members, double phi) {
  SinCos env = ideal_envelopes(phi);
  for (WindingStage stage :
       {WindingStage::kFundamental, WindingStage::kAdditive, WindingStage::kGain, WindingStage::kOffset}) {
    for (const EnvelopeMember& m : members) m.effect->windings(m.values, stage, phi, env);
  }
  return env;
}

SignalValues EnvelopeSeries::at(const AngleBasis& basis) const {
  SignalValues out;
  const bool filtered = basis.rd_filtered();
  for (std::size_t i = 0; i < k.size(); ++i) {
    const int n = k[i];
    const double c = basis.env_cos(n), s = basis.env_sin(n);
    out.sa += e_cos[i] * c + e_sin[i] * s;
    if (filtered) {
      // e_cos rd_cos(n) + e_sin rd_sin(n) with rd_cos = Re(h) c - Im(h) s and
      // rd_sin = Re(h) s + Im(h) c (signature.h): one loop response per order.
      const std::complex<double> h = basis.rd_response(n);
      out.rd += h.real() * (e_cos[i] * c + e_sin[i] * s) + h.imag() * (e_sin[i] * c - e_cos[i] * s);
    }
    out.sr += r_cos[i] * c + r_sin[i] * s;
  }
  // Without a loop the R/D angle sees the envelopes' error term for term (the same sums).
  if (!filtered) out.rd = out.sa;
  return out;
}

EnvelopeSeries envelope_series(std::span<const EnvelopeMember> members) {
  Samples e{}, r{};
  for (int j = 0; j < kGridPoints; ++j) {
    const double phi = grid_angle(j);
    const SinCos env = envelopes_through(members, phi);
    e[static_cast<std::size_t>(j)] = wrap_pi(phi - std::atan2(env.s, env.c));
    r[static_cast<std::size_t>(j)] = std::hypot(env.s, env.c) - 1.0;
  }
  return transform(e, r, kDropBelow);
}

EnvelopeSeries envelope_derivative_series(std::span<const EnvelopeMember> members, std::size_t member,
                                          std::size_t param) {
  const Effect& effect = *members[member].effect;
  const ParamInfo& info = effect.params()[param];
  // Central differences of the hooks: truncation h^2 f''' / 6 ~ 2e-11 and rounding
  // 1e-16 / h ~ 1e-11 relative (balanced at h = 1e-5 of a unit range).
  const double h = 1e-5 * std::max(1.0, info.max - info.min);
  std::vector<double> up(members[member].values.begin(), members[member].values.end());
  std::vector<double> down = up;
  up[param] += h;
  down[param] -= h;
  std::vector<EnvelopeMember> plus(members.begin(), members.end()), minus(members.begin(), members.end());
  plus[member].values = up;
  minus[member].values = down;
  Samples de{}, dr{};
  for (int j = 0; j < kGridPoints; ++j) {
    const double phi = grid_angle(j);
    const SinCos env = envelopes_through(members, phi);
    const SinCos a = envelopes_through(plus, phi);
    const SinCos b = envelopes_through(minus, phi);
    const double ds = (a.s - b.s) / (2.0 * h), dc = (a.c - b.c) / (2.0 * h);
    const double rho2 = env.s * env.s + env.c * env.c;
    const double rho = std::sqrt(rho2);
    // e = phi - atan2(s, c): de = -(c ds - s dc) / rho^2; r = rho - 1: dr = (s ds + c dc) / rho.
    de[static_cast<std::size_t>(j)] = rho2 > 0.0 ? (env.s * dc - env.c * ds) / rho2 : 0.0;
    dr[static_cast<std::size_t>(j)] = rho > 0.0 ? (env.s * ds + env.c * dc) / rho : 0.0;
  }
  // Rounding leaves ~1e-11 of the column's scale in every order: drop what is below
  // 1e-9 of the largest sample (the column's shape, not the prediction, rests on it).
  double scale = 0.0;
  for (std::size_t j = 0; j < kGridPoints; ++j) scale = std::max({scale, std::abs(de[j]), std::abs(dr[j])});
  return transform(de, dr, std::max(kDropBelow, 1e-9 * scale));
}

}  // namespace resolver
