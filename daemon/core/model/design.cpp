#include "daemon/core/model/design.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace resolver {

std::string_view nuisance_name(Nuisance n) {
  switch (n) {
    case Nuisance::kRdConstant: return "nuisance.rd_constant";
    case Nuisance::kSaConstant: return "nuisance.sincos_angle_constant";
    case Nuisance::kScGain: return "nuisance.sincos_gain";
    case Nuisance::kIdConstant: return "nuisance.i_d";
    case Nuisance::kIqConstant: return "nuisance.i_q";
  }
  return "nuisance.?";
}

double to_internal(const ParamInfo& p, double value) {
  if (p.nonlinear && p.scale == FitScale::kInverseSquare) return value > 0.0 ? 1.0 / (value * value) : 0.0;
  return value;
}

double from_internal(const ParamInfo& p, double z) {
  if (p.nonlinear && p.scale == FitScale::kInverseSquare) return z > 0.0 ? 1.0 / std::sqrt(z) : 0.0;
  return z;
}

void RowJacobian::resize(int k) {
  rd.resize(k);
  sa.resize(k);
  sr.resize(k);
  d.resize(k);
  q.resize(k);
}

void RowJacobian::set_zero() {
  rd.setZero();
  sa.setZero();
  sr.setZero();
  d.setZero();
  q.setZero();
}

namespace {

std::vector<double> neutral_values(const Effect& e) {
  std::vector<double> v;
  for (const ParamInfo& p : e.params()) v.push_back(p.neutral);
  return v;
}

/// The largest factor a positive nonlinear parameter moves by in one step (Design::step).
constexpr double kScaleStep = 2.0;

/// Finite-difference step of a nonlinear parameter's internal coordinate z.
double fd_step(const ParamInfo& p, double z) {
  if (p.scale == FitScale::kInverseSquare) {
    // z = 1/omega_n^2: from the ideal converter, a loop 10x faster than the range's top.
    const double floor_step = 1.0 / (p.max * p.max) * 100.0;
    return std::max(1e-3 * std::abs(z), floor_step);
  }
  return std::max(1e-4 * std::abs(z), 1e-7 * (p.max - p.min));
}

}  // namespace

Design::Design(const ModelSpec& spec, const std::vector<std::vector<double>>& values, std::vector<Nuisance> nuisances)
    : nuisances_(std::move(nuisances)) {
  for (std::size_t i = 0; i < spec.terms.size(); ++i) {
    const ModelTerm& t = spec.terms[i];
    DesignTerm d{t.effect, t.params, i < values.size() && !values[i].empty() ? values[i] : neutral_values(*t.effect),
                 false};
    if (d.values.size() != t.effect->params().size()) {
      throw std::invalid_argument("design: values of " + std::string(t.effect->name()) + " have the wrong size");
    }
    terms_.push_back(std::move(d));
  }
  rebuild();
}

void Design::add_candidate(const ModelTerm& term) {
  DesignTerm added{term.effect, term.params, neutral_values(*term.effect), true};
  if (!term.effect->envelope_only() && !term.effect->linear_in_params()) {
    for (const DesignTerm& t : terms_) {
      if (t.candidate || t.effect != term.effect) continue;
      added.values = t.values;
      added.replaces_model_term = true;
    }
  }
  terms_.push_back(std::move(added));
  rebuild();
}

bool Design::stood_in_for(std::size_t i, std::size_t override_term, const std::vector<double>* override_values) const {
  if (override_values == nullptr || override_term >= terms_.size() || i == override_term) return false;
  const DesignTerm& o = terms_[override_term];
  return o.replaces_model_term && !terms_[i].candidate && terms_[i].effect == o.effect;
}

void Design::set_parts(int parts) {
  if (parts < 1) throw std::invalid_argument("design: a pooled fit needs at least one part");
  frame_shifts_.resize(static_cast<std::size_t>(parts), frame_shifts_.front());
  rebuild();
}

void Design::rebuild() {
  term_first_.clear();
  int k = nuisance_columns();
  std::size_t widest = 0;
  for (const DesignTerm& t : terms_) {
    term_first_.push_back(k);
    k += static_cast<int>(t.params.size());
    widest = std::max(widest, t.effect->params().size());
  }
  columns_ = k;
  scratch_.resize(widest);
  envelope_.valid = false;
}

std::vector<std::string> Design::column_names() const {
  std::vector<std::string> out;
  for (int part = 0; part < parts(); ++part) {
    for (Nuisance n : nuisances_) {
      out.push_back(parts() == 1 ? std::string(nuisance_name(n))
                                 : std::string(nuisance_name(n)) + "[" + std::to_string(part + 1) + "]");
    }
  }
  for (const DesignTerm& t : terms_) {
    for (int p : t.params) {
      out.push_back(std::string(t.effect->name()) + "." +
                    std::string(t.effect->params()[static_cast<std::size_t>(p)].name));
    }
  }
  return out;
}

bool Design::nonlinear() const {
  for (const DesignTerm& t : terms_) {
    if (t.candidate) continue;
    // Envelope effects enter through atan2 and hypot (and with each other).
    if (t.effect->shapes_basis() || t.effect->envelope_only()) return true;
    for (int p : t.params) {
      if (t.effect->params()[static_cast<std::size_t>(p)].nonlinear) return true;
    }
  }
  return false;
}

Eigen::VectorXd Design::z() const {
  Eigen::VectorXd z = Eigen::VectorXd::Zero(columns_);
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const auto ps = t.effect->params();
    for (std::size_t k = 0; k < t.params.size(); ++k) {
      const auto p = static_cast<std::size_t>(t.params[k]);
      const int col = term_first_[i] + static_cast<int>(k);
      if (ps[p].polar == Polar::kAmplitude) {
        z[col] = t.values[p] * std::cos(t.values[p + 1]);
      } else if (ps[p].polar == Polar::kPhase) {
        z[col] = t.values[p - 1] * std::sin(t.values[p]);
      } else {
        z[col] = to_internal(ps[p], t.values[p]);
      }
    }
  }
  return z;
}

void Design::step(const Eigen::VectorXd& dz) {
  envelope_.valid = false;
  const Eigen::VectorXd z0 = z();
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    DesignTerm& t = terms_[i];
    if (t.candidate) continue;
    const auto ps = t.effect->params();
    for (std::size_t k = 0; k < t.params.size(); ++k) {
      const auto p = static_cast<std::size_t>(t.params[k]);
      const int col = term_first_[i] + static_cast<int>(k);
      if (ps[p].polar == Polar::kAmplitude) {
        const double x = z0[col] + dz[col];
        const double y = z0[col + 1] + dz[col + 1];  // the phase is the next column (params ascending)
        t.values[p] = std::hypot(x, y);
        t.values[p + 1] = std::atan2(y, x);
      } else if (ps[p].polar == Polar::kPhase) {
        continue;  // set with its amplitude
      } else {
        double z = z0[col] + dz[col];
        if (ps[p].nonlinear && ps[p].scale == FitScale::kInverseSquare) z = std::max(z, 0.0);
        double v = from_internal(ps[p], z);
        if (ps[p].nonlinear && ps[p].scale == FitScale::kLinear && ps[p].min > 0.0) {
          // A positive scale parameter (a loop's damping ratio: the resonance peak goes as
          // 1 / (2 zeta)) moves by at most a factor kScaleStep per step: linearised at 0.7,
          // a lightly damped loop's (0.05) first step went to the bound 0.01, where the
          // balance has no steady state and the columns no longer separate.
          v = std::clamp(v, t.values[p] / kScaleStep, t.values[p] * kScaleStep);
        }
        t.values[p] = std::clamp(v, ps[p].min, ps[p].max);
      }
    }
  }
}

bool Design::pushed_past_bound(int col, double dz) const {
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const int k = col - term_first_[i];
    if (k < 0 || k >= static_cast<int>(t.params.size())) continue;
    const auto p = static_cast<std::size_t>(t.params[static_cast<std::size_t>(k)]);
    const ParamInfo& info = t.effect->params()[p];
    if (info.polar != Polar::kNone) return false;
    const double z = to_internal(info, t.values[p]);
    double zmin = 0.0, zmax = 0.0;
    if (info.scale == FitScale::kInverseSquare) {
      // z = 1/value^2 with value 0 the neutral (an ideal converter, infinitely fast): z runs
      // from 0 (ideal; the range's top, 1e6 rad/s, is z = 1e-12) up to 1/min^2, unbounded
      // for min = 0. Taken as [z(min), z(max)] = [0, 1e-12], every fitted loop sat "at the
      // top bound", and a step to a slower loop was held: omega_n only ever rose (3047 for
      // a 3000 rad/s loop) and its standard error printed 0 (its column left the solution).
      zmin = 0.0;
      zmax = info.min > 0.0 ? to_internal(info, info.min) : std::numeric_limits<double>::infinity();
    } else {
      zmin = std::min(info.min, info.max);
      zmax = std::max(info.min, info.max);
    }
    const double tol = 1e-12 * (std::isfinite(zmax) ? std::max(1.0, zmax - zmin) : 1.0);
    return (z <= zmin + tol && dz < 0.0) || (z >= zmax - tol && dz > 0.0);
  }
  return false;
}

std::vector<double> Design::values_with(std::size_t term, int column_in_term, double dz) const {
  const DesignTerm& t = terms_[term];
  std::vector<double> v = t.values;
  const auto p = static_cast<std::size_t>(t.params[static_cast<std::size_t>(column_in_term)]);
  const ParamInfo& info = t.effect->params()[p];
  if (info.polar != Polar::kNone) {
    // A polar pair moves along its Cartesian coordinate (x for the amplitude's
    // column, y for the phase's), as its columns are defined (effect.h).
    const std::size_t amp = info.polar == Polar::kAmplitude ? p : p - 1;
    double x = v[amp] * std::cos(v[amp + 1]), y = v[amp] * std::sin(v[amp + 1]);
    (info.polar == Polar::kAmplitude ? x : y) += dz;
    v[amp] = std::hypot(x, y);
    v[amp + 1] = std::atan2(y, x);
    return v;
  }
  v[p] = from_internal(info, to_internal(info, v[p]) + dz);
  return v;
}

std::vector<EnvelopeMember> Design::envelope_members(std::size_t override_term,
                                                     const std::vector<double>* override_values,
                                                     std::size_t with_candidate) const {
  std::vector<EnvelopeMember> out;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const bool override = override_values != nullptr && i == override_term;
    if (!t.effect->envelope_only() || (t.candidate && !override && i != with_candidate)) continue;
    out.push_back(EnvelopeMember{t.effect, override ? std::span<const double>(*override_values)
                                                    : std::span<const double>(t.values)});
  }
  return out;
}

const Design::EnvelopeCache& Design::envelope() const {
  if (envelope_.valid) return envelope_;
  EnvelopeCache c;
  const std::vector<EnvelopeMember> model = envelope_members(terms_.size(), nullptr, terms_.size());
  c.series = envelope_series(model);
  c.columns.resize(terms_.size());
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    if (!t.effect->envelope_only()) continue;
    if (!t.candidate) c.model_terms.push_back(i);
    // The column of a candidate is its derivative at the model's point: the model's
    // members plus the candidate (at its neutral values: the envelopes unchanged).
    const std::vector<EnvelopeMember> members =
        t.candidate ? envelope_members(terms_.size(), nullptr, i) : model;
    std::size_t member = 0;
    while (members[member].values.data() != t.values.data()) ++member;
    for (int p : t.params) {
      c.columns[i].push_back(envelope_derivative_series(members, member, static_cast<std::size_t>(p)));
    }
  }
  c.valid = true;
  envelope_ = std::move(c);
  return envelope_;
}

const LoopCorrection& Design::loop_correction(const TrackingLoopParams& loop) const {
  const EnvelopeCache& env = envelope();
  for (const LoopCorrection& c : env.loops) {
    if (c.loop()["omega_n"] == loop["omega_n"] && c.loop()["zeta"] == loop["zeta"]) return c;
  }
  // A fit point needs the model's loop and one moved per fitted loop parameter.
  constexpr std::size_t kLoopsKept = 4;
  if (envelope_.loops.size() >= kLoopsKept) envelope_.loops.erase(envelope_.loops.begin());
  envelope_.loops.emplace_back(env.series, loop);
  return envelope_.loops.back();
}

std::int64_t Design::loop_balance_unconverged(std::span<const FitRow> rows) const {
  // The loop is the converter's, not the row's: one transform per part, not per row.
  std::vector<std::optional<TrackingLoopParams>> loops(static_cast<std::size_t>(parts()));
  std::int64_t out = 0;
  for (const FitRow& r : rows) {
    if (!r.fitted() || !r.has(FitRow::kHasRd)) continue;
    std::optional<TrackingLoopParams>& loop = loops[r.part];
    if (!loop) loop = transform(r.sig, r.part, terms_.size(), nullptr).loop;
    if (tracking_loop_active(*loop) && !loop_correction(*loop).converged_at(r.sig.omega)) ++out;
  }
  return out;
}

BasisTransform Design::transform(const SignatureRow& row, int part, std::size_t extra_term,
                                 const std::vector<double>* extra_values) const {
  BasisTransform tr;
  tr.shift = frame_shift(part);
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const bool override = extra_values != nullptr && i == extra_term;
    if ((t.candidate && !override) || stood_in_for(i, extra_term, extra_values)) continue;
    t.effect->configure_basis(row, override ? *extra_values : t.values, tr);
  }
  return tr;
}

SignalValues Design::predict_with(const SignatureRow& row, int part, AngleBasis& basis, std::size_t override_term,
                                  const std::vector<double>* override_values, const BasisTransform* tr) const {
  basis.set(row, tr != nullptr ? *tr : transform(row, part, override_term, override_values));
  SignalValues pred;
  const bool envelope_override = override_values != nullptr && override_term < terms_.size() &&
                                 terms_[override_term].effect->envelope_only();
  // Every envelope effect at once, exactly (the cached series unless one is moved).
  pred += envelope_override ? envelope_series(envelope_members(override_term, override_values, terms_.size()))
                                  .at(basis)
                            : envelope().series.at(basis);
  // The converter's loop gain is the envelopes' radius: what its linear filter misses
  // at real magnitudes (loop_correction.h).
  if (basis.rd_filtered()) pred.rd += loop_correction(basis.transform().loop).at(basis);
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const bool override = override_values != nullptr && i == override_term;
    if ((t.candidate && !override) || stood_in_for(i, override_term, override_values)) continue;
    if (t.effect->envelope_only()) continue;
    const std::vector<double>& v = override ? *override_values : t.values;
    if (!t.effect->linear_in_params()) {
      t.effect->contribution(row, basis, v, pred);
      continue;
    }
    SignatureColumns cols(std::span<SignalValues>(scratch_.data(), t.effect->params().size()));
    cols.clear();
    t.effect->signature(row, basis, v, cols);
    for (int p : t.params) {
      const SignalValues& c = cols.col(static_cast<std::size_t>(p));
      const double x = v[static_cast<std::size_t>(p)];
      pred.rd += c.rd * x;
      pred.sa += c.sa * x;
      pred.sr += c.sr * x;
      pred.d += c.d * x;
      pred.q += c.q * x;
    }
  }
  // The position error's constant in the log's frame: the sensor's zero (header).
  pred.rd -= frame_shift(part);
  pred.sa -= frame_shift(part);
  return pred;
}

SignalValues Design::predict(const FitRow& row, AngleBasis& basis) const {
  return predict_with(row.sig, row.part, basis, terms_.size(), nullptr);
}

namespace {

struct RowsHistory {
  std::span<const FitRow> rows;
};

/// theta at time t from the rows before `index` (linear between two rows; NaN
/// before the first row or across a gap of more than 3 row spacings).
double history_angle(const void* context, std::size_t index, double t) {
  const auto& rows = static_cast<const RowsHistory*>(context)->rows;
  if (index >= rows.size()) return std::nan("");
  std::size_t k = index;
  while (k > 0 && rows[k].sig.t > t) {
    const double gap = rows[k].sig.t - rows[k - 1].sig.t;
    if (k < index && gap > 3.0 * (rows[k + 1].sig.t - rows[k].sig.t)) return std::nan("");
    --k;
  }
  if (rows[k].sig.t > t) return std::nan("");
  if (k == index) return rows[k].sig.theta;
  const FitRow& a = rows[k];
  const FitRow& b = rows[k + 1];
  const double f = (t - a.sig.t) / (b.sig.t - a.sig.t);
  return a.sig.theta + f * (b.sig.theta - a.sig.theta);
}

}  // namespace

SignalValues Design::predict(std::span<const FitRow> rows, std::size_t i, AngleBasis& basis) const {
  const RowsHistory h{rows};
  SignatureRow row = rows[i].sig;
  row.history = AngleHistory{&h, &history_angle, i};
  return predict_with(row, rows[i].part, basis, terms_.size(), nullptr);
}

void Design::evaluate(std::span<const FitRow> rows, std::size_t i, AngleBasis& basis, SignalValues& prediction,
                      RowJacobian& jac) const {
  const RowsHistory h{rows};
  SignatureRow row = rows[i].sig;
  row.history = AngleHistory{&h, &history_angle, i};
  evaluate_row(row, rows[i].part, basis, prediction, jac);
}

namespace {

/// [rad] the shift step of Design::shift_slope: as fd_step's for a parameter of range 1.
constexpr double kShiftStep = 1e-7;

SignalValues difference(const SignalValues& a, const SignalValues& b, double h) {
  return SignalValues{.rd = (a.rd - b.rd) / h, .sa = (a.sa - b.sa) / h, .sr = (a.sr - b.sr) / h, .d = (a.d - b.d) / h,
                      .q = (a.q - b.q) / h};
}

/// Whether two transforms differ in their shift only (the same loop and delay).
bool only_shift_differs(const BasisTransform& a, const BasisTransform& b) {
  return a.delay == b.delay && a.loop["omega_n"] == b.loop["omega_n"] && a.loop["zeta"] == b.loop["zeta"];
}

}  // namespace

SignalValues Design::shift_slope(const SignatureRow& row, int part, const SignalValues& prediction) const {
  BasisTransform moved = transform(row, part, terms_.size(), nullptr);
  moved.shift += kShiftStep;
  return difference(predict_with(row, part, shifted_, terms_.size(), nullptr, &moved), prediction, kShiftStep);
}

void Design::evaluate_row(const SignatureRow& row, int part, AngleBasis& basis, SignalValues& prediction,
                          RowJacobian& jac) const {
  if (jac.rd.size() != columns_) jac.resize(columns_);
  jac.set_zero();
  prediction = predict_with(row, part, basis, terms_.size(), nullptr);
  int col = nuisance_column(part, 0);  // this row's part's own constants (header)
  for (Nuisance n : nuisances_) {
    switch (n) {
      case Nuisance::kRdConstant: jac.rd[col] = 1.0; break;
      case Nuisance::kSaConstant: jac.sa[col] = 1.0; break;
      // The envelopes' amplitude scales the modelled radius: sr = g (1 + r) - 1 is
      // exactly linear in g - 1 with the column 1 + r (an additive column would leave
      // (g - 1) r: 5e-3 at alpha = 0.15, fifty times a 16-bit bench's floor).
      case Nuisance::kScGain: jac.sr[col] = 1.0 + prediction.sr; break;
      case Nuisance::kIdConstant: jac.d[col] = 1.0; break;
      case Nuisance::kIqConstant: jac.q[col] = 1.0; break;
    }
    ++col;
  }
  col = nuisance_columns();
  AngleBasis& shifted = shifted_;  // numeric derivatives move the basis; `basis` stays at the model's
  std::optional<SignalValues> slope;  // shift_slope, once per row when needed
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const DesignTerm& t = terms_[i];
    const auto ps = t.effect->params();
    if (t.effect->envelope_only()) {
      // Exact derivatives of the joint envelope model (envelope_spectrum.h).
      const std::vector<EnvelopeSeries>& d = envelope().columns[i];
      for (std::size_t k = 0; k < t.params.size(); ++k, ++col) {
        const SignalValues c = d[k].at(basis);
        jac.rd[col] = c.rd;
        jac.sa[col] = c.sa;
        jac.sr[col] = c.sr;
      }
      continue;
    }
    SignatureColumns cols(std::span<SignalValues>(scratch_.data(), ps.size()));
    cols.clear();
    t.effect->signature(row, basis, t.values, cols);
    for (std::size_t k = 0; k < t.params.size(); ++k, ++col) {
      const auto p = static_cast<std::size_t>(t.params[k]);
      SignalValues c = cols.col(p);
      // Numeric through the whole prediction when the parameter is nonlinear or its
      // effect moves the basis (a mounting offset turns every winding error with the
      // seen angle: a cross term its own column does not carry).
      if (ps[p].nonlinear || t.effect->shapes_basis()) {
        const double z = ps[p].polar != Polar::kNone ? 0.0 : to_internal(ps[p], t.values[p]);
        const double h = fd_step(ps[p], z);
        const std::vector<double> moved = values_with(i, static_cast<int>(k), h);
        BasisTransform at, to;  // a candidate's own action on the basis, before and moved
        if (t.candidate) {
          t.effect->configure_basis(row, t.values, at);
          t.effect->configure_basis(row, moved, to);
        }
        if (t.candidate && only_shift_differs(at, to)) {
          // A candidate that moves the seen angle only (eccentricity, mechanical harmonics,
          // mounting offset, backlash): the model's change is its slope in the shift times
          // the shift's, plus the candidate's own column (its signature, above); the same
          // first-order derivative without a whole prediction per column.
          if (!slope) slope = shift_slope(row, part, prediction);
          const double ds = (to.shift - at.shift) / h;
          c = SignalValues{.rd = c.rd + slope->rd * ds, .sa = c.sa + slope->sa * ds, .sr = c.sr + slope->sr * ds,
                           .d = c.d + slope->d * ds, .q = c.q + slope->q * ds};
        } else {
          c = difference(predict_with(row, part, shifted, i, &moved), prediction, h);
        }
      }
      jac.rd[col] = c.rd;
      jac.sa[col] = c.sa;
      jac.sr[col] = c.sr;
      jac.d[col] = c.d;
      jac.q[col] = c.q;
    }
  }
}

}  // namespace resolver
