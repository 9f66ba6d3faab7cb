#include "daemon/core/discovery/pool.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/effects/registry.h"

namespace resolver {

namespace {

/// [s] between one log's last row and the next one's first: far beyond any delay,
/// whiteness lag or history gap test (three row spacings), so nothing reaches across.
constexpr double kGapBetweenLogs = 10.0;

/// Rows-weighted pooled variance of one group's floors.
FloorEstimate pool_floor(const std::vector<const FloorEstimate*>& f, const std::vector<double>& weight) {
  FloorEstimate out;
  double w = 0.0, chosen = 0.0, sd = 0.0, ss = 0.0, sq = 0.0;
  bool same_source = true;
  for (std::size_t i = 0; i < f.size(); ++i) {
    w += weight[i];
    chosen += weight[i] * f[i]->chosen * f[i]->chosen;
    sd += weight[i] * f[i]->second_difference * f[i]->second_difference;
    ss += weight[i] * f[i]->standstill * f[i]->standstill;
    sq += weight[i] * f[i]->quantization * f[i]->quantization;
    out.standstill_samples += f[i]->standstill_samples;
    same_source = same_source && f[i]->source == f.front()->source;
  }
  if (!(w > 0.0)) return *f.front();
  out.chosen = std::sqrt(chosen / w);
  out.second_difference = std::sqrt(sd / w);  // NaN when any log's is
  out.standstill = std::sqrt(ss / w);
  out.quantization = std::sqrt(sq / w);
  out.source = same_source ? f.front()->source : "pooled: each log's own source";
  return out;
}

/// Each log's floors weighted by its rows: the pool's.
FloorReport pool_floors(const std::vector<PreparedLog>& logs) {
  std::vector<const FloorReport*> floors;
  std::vector<double> rows;
  for (const PreparedLog& l : logs) {
    floors.push_back(&l.floors);
    rows.push_back(static_cast<double>(l.fitted_rows()));
  }
  return pool_floor_reports(floors, rows);
}

void add_outliers(std::vector<OutlierSignal>& into, const std::vector<OutlierSignal>& add) {
  for (const OutlierSignal& o : add) {
    const auto same = std::find_if(into.begin(), into.end(), [&](const OutlierSignal& e) { return e.signal == o.signal; });
    if (same == into.end()) {
      into.push_back(o);
      continue;
    }
    same->count += o.count;
    same->largest = std::max(same->largest, o.largest);
    same->scale = std::max(same->scale, o.scale);
  }
}

/// True when `name` ("effect.param") is the phase of a polar pair (effect.h Polar).
bool is_phase(const std::string& name) {
  const std::size_t dot = name.find('.');
  const Effect* e = dot == std::string::npos ? nullptr : find_effect(name.substr(0, dot));
  if (e == nullptr) return false;
  const int p = find_param(*e, name.substr(dot + 1));
  return p >= 0 && e->params()[static_cast<std::size_t>(p)].polar == Polar::kPhase;
}

/// The logs' rows one after the other: part index, time running on, blocks numbered on.
void append_rows(PreparedLog& pool, PreparedLog& log, std::uint16_t part, double& t_offset,
                 std::int32_t& block_offset, std::size_t sample_offset) {
  double t_last = 0.0;
  std::int32_t block_last = 0;
  for (FitRow& r : log.rows) {
    r.part = part;
    r.sig.t += t_offset;
    r.block += block_offset;
    t_last = std::max(t_last, r.sig.t);
    block_last = std::max(block_last, r.block);
  }
  for (std::size_t s : log.sample_of_row) pool.sample_of_row.push_back(s + sample_offset);
  pool.rows.insert(pool.rows.end(), log.rows.begin(), log.rows.end());
  t_offset = t_last + kGapBetweenLogs;
  block_offset = block_last + 1;
}

/// Notes every log has once; the others prefixed by their log.
void pool_notes(PreparedLog& pool, const std::vector<PreparedLog>& logs, const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < logs.size(); ++i) {
    for (const std::string& n : logs[i].notes) {
      const bool everywhere = std::all_of(logs.begin(), logs.end(), [&](const PreparedLog& l) {
        return std::find(l.notes.begin(), l.notes.end(), n) != l.notes.end();
      });
      const std::string note = everywhere ? n : names[i] + ": " + n;
      if (std::find(pool.notes.begin(), pool.notes.end(), note) == pool.notes.end()) pool.notes.push_back(note);
    }
  }
}

}  // namespace

PreparedLog pool_logs(std::vector<PreparedLog> logs, const std::vector<std::string>& names) {
  if (logs.size() < 2 || logs.size() != names.size()) {
    throw std::invalid_argument("a pooled fit needs two or more logs, each with its name");
  }
  if (logs.size() > std::numeric_limits<std::uint16_t>::max()) {
    throw std::invalid_argument(fmt::format("{} logs: a pooled fit takes at most 65535", logs.size()));
  }
  const PreparedLog& first = logs.front();
  for (std::size_t i = 1; i < logs.size(); ++i) {
    check_same_layout(pool_layout(first), pool_layout(logs[i]), names.front(), names[i]);
  }
  PreparedLog pool;
  pool.p_r = first.p_r;
  pool.p = first.p;
  pool.reference = first.reference;
  pool.reference_aligned = first.reference_aligned;
  pool.rd = first.rd;
  pool.sincos = first.sincos;
  pool.currents = first.currents;
  pool.quanta = first.quanta;
  pool.part_names = names;
  pool.floors = pool_floors(logs);
  double t_offset = 0.0, rows = 0.0, amplitude = 0.0, period = 0.0;
  std::int32_t block_offset = 0;
  std::size_t sample_offset = 0;
  std::vector<std::string> fold_rules;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    PreparedLog& l = logs[i];
    const auto n = static_cast<double>(l.rows.size());
    rows += n;
    amplitude += n * l.amplitude;
    period += n * l.sample_period;
    add_motion(pool.motion, l.motion, i == 0);
    add_outliers(pool.outliers, l.outliers);
    pool.samples_in += l.samples_in;
    pool.without_angle += l.without_angle;
    pool.without_reference += l.without_reference;
    pool.excluded_direction += l.excluded_direction;
    pool.unusable_self_calibration += l.unusable_self_calibration;
    fold_rules.push_back(names[i] + ": " + l.fold_rule);
    append_rows(pool, l, static_cast<std::uint16_t>(i), t_offset, block_offset, sample_offset);
    sample_offset += static_cast<std::size_t>(l.samples_in);
  }
  pool.motion.span_s += kGapBetweenLogs * static_cast<double>(logs.size() - 1);
  // The rows are each log's own: sin/cos radii against its own amplitude, times
  // from its own clock. These two only describe the pool.
  pool.amplitude = amplitude / rows;
  pool.sample_period = period / rows;
  pool.fold_rule = "each log's own folds (" + fmt::format("{}", fmt::join(fold_rules, "; ")) + ")";
  pool_notes(pool, logs, names);
  pool.notes.push_back(fmt::format("pooled fit of {} logs: the sensor's parameters shared, each log's reference zero, "
                                   "envelope amplitude and operating point its own; time runs on across the logs in "
                                   "the order given",
                                   logs.size()));
  return pool;
}

namespace {

/// Inverse-variance mean of the logs in `in` except `skip`, and its standard error
/// (NaN when none is left).
std::pair<double, double> weighted_mean(const std::vector<double>& x, const std::vector<double>& w,
                                        const std::vector<bool>& in, std::size_t skip) {
  double sw = 0.0, swx = 0.0;
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (j == skip || !in[j]) continue;
    sw += w[j];
    swx += w[j] * x[j];
  }
  if (!(sw > 0.0)) return {std::nan(""), std::nan("")};
  return {swx / sw, 1.0 / std::sqrt(sw)};
}

double z_against(double x, double w, std::pair<double, double> others) {
  return (x - others.first) / std::sqrt(1.0 / w + others.second * others.second);
}

}  // namespace

std::vector<PoolDisagreement> compare_with_pool(const ModelFit& pooled, const std::vector<ModelFit>& alone,
                                                const std::vector<std::string>& names) {
  std::vector<PoolDisagreement> out;
  const std::size_t n = std::min(alone.size(), names.size());
  for (const ModelParameter& q : pooled.params) {
    // Each log's own value of this parameter (weight 0: its fit failed or gave no error).
    std::vector<double> x(n, 0.0), w(n, 0.0);
    std::vector<bool> in(n, false);
    for (std::size_t i = 0; i < n; ++i) {
      for (const ModelParameter& p : alone[i].params) {
        if (p.name != q.name || !std::isfinite(p.value) || !(p.std_error > 0.0)) continue;
        // A phase (eccentricity's, a polar harmonic's) is compared on the circle: 3.1
        // and -3.1 rad are 0.08 apart, not 6.2.
        x[i] = is_phase(p.name) ? q.value + wrap_pi(p.value - q.value) : p.value;
        w[i] = 1.0 / (p.std_error * p.std_error);
        in[i] = true;
      }
    }
    // The consensus: while three or more logs remain, the one furthest from the
    // rest (leave one out) beyond kPoolDisagreementZ leaves it. An odd log then
    // does not make its fellows look odd; of two logs that differ, neither is the
    // odd one, and both are named.
    for (;;) {
      const auto remaining = static_cast<std::size_t>(std::count(in.begin(), in.end(), true));
      if (remaining < 3) break;
      std::size_t worst = n;
      double worst_z = kPoolDisagreementZ;
      for (std::size_t i = 0; i < n; ++i) {
        if (!in[i]) continue;
        const double z = std::abs(z_against(x[i], w[i], weighted_mean(x, w, in, i)));
        if (z > worst_z) {
          worst_z = z;
          worst = i;
        }
      }
      if (worst == n) break;
      in[worst] = false;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!(w[i] > 0.0)) continue;
      const std::pair<double, double> others = weighted_mean(x, w, in, i);
      if (!std::isfinite(others.first)) continue;
      out.push_back({names[i], q.name, x[i], 1.0 / std::sqrt(w[i]), others.first, others.second, q.value,
                     z_against(x[i], w[i], others)});
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return std::abs(a.z) > std::abs(b.z); });
  return out;
}

PooledLogs prepare_pooled(const std::vector<const DiscoveryInput*>& inputs, const std::vector<std::string>& names,
                          const PrepareOptions& options) {
  PooledLogs out;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    try {
      out.logs.push_back(prepare_log(*inputs[i], options));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(names[i] + ": " + e.what());
    }
  }
  out.pool = pool_logs(out.logs, names);
  return out;
}

LogComparison compare_logs(const PooledLogs& pooled, const std::vector<std::string>& names, const ModelFit& fit,
                           std::span<const std::string> effects, const DiscoveryOptions& options) {
  LogComparison out;
  DiscoveryOptions alone_options = options;
  alone_options.progress = nullptr;
  for (const PreparedLog& log : pooled.logs) {
    try {
      out.alone.push_back(fit_prepared(log, effects, alone_options));
      out.alone_failed.emplace_back();
    } catch (const std::invalid_argument& e) {
      out.alone.emplace_back();
      out.alone_failed.emplace_back(e.what());
    }
  }
  out.comparisons = compare_with_pool(fit, out.alone, names);
  return out;
}

std::vector<std::string> disagreement_notes(const std::vector<PoolDisagreement>& comparisons) {
  std::vector<std::string> out;
  for (const PoolDisagreement& d : comparisons) {
    if (std::abs(d.z) <= kPoolDisagreementZ) break;  // largest |z| first
    out.push_back(fmt::format(
        "{} disagrees with the other logs on {}: {:.6g} +- {:.2g} fitted alone against their {:.6g} +- {:.2g} "
        "(z = {:.1f}): a parameter that changed between runs, a log of another sensor, or an effect the model "
        "lacks that differs between the logs (speed, direction, load)",
        d.log, d.parameter, d.value, d.std_error, d.others, d.others_std_error, d.z));
  }
  return out;
}

PooledExplanation explain_pooled(const std::vector<const DiscoveryInput*>& inputs, const std::vector<std::string>& names,
                                 std::span<const std::string> effects, const DiscoveryOptions& options, bool explain) {
  PooledExplanation out;
  out.names = names;
  const PooledLogs pooled = prepare_pooled(inputs, names, options.prepare);
  if (explain) out.pooled = explain_prepared(pooled.pool, effects, options);
  else out.pooled.fit = fit_prepared(pooled.pool, effects, options);
  out.logs = compare_logs(pooled, names, out.pooled.fit, effects, options);
  for (std::string& n : disagreement_notes(out.logs.comparisons)) out.pooled.fit.notes.push_back(std::move(n));
  return out;
}

FloorReport pool_floor_reports(const std::vector<const FloorReport*>& floors, const std::vector<double>& rows) {
  std::vector<const FloorEstimate*> rd, sc, cur;
  for (const FloorReport* f : floors) {
    rd.push_back(&f->rd);
    sc.push_back(&f->sc);
    cur.push_back(&f->cur);
  }
  return {pool_floor(rd, rows), pool_floor(sc, rows), pool_floor(cur, rows)};
}

void add_motion(MotionSummary& into, const MotionSummary& m, bool first) {
  into.samples += m.samples;
  into.moving += m.moving;
  into.standstill += m.standstill;
  into.forward += m.forward;
  into.backward += m.backward;
  into.reversals += m.reversals;
  into.standstills += m.standstills;
  into.travelled += m.travelled;
  into.span_s += m.span_s;
  into.omega_min = first ? m.omega_min : std::min(into.omega_min, m.omega_min);
  into.omega_max = first ? m.omega_max : std::max(into.omega_max, m.omega_max);
  into.angle_noise = std::max(into.angle_noise, m.angle_noise);
}

PoolLayout pool_layout(const PreparedLog& log) {
  return {log.p_r, log.p, log.reference, log.reference_aligned, log.rd, log.sincos, log.currents};
}

void check_same_layout(const PoolLayout& first, const PoolLayout& other, const std::string& first_name,
                       const std::string& name) {
  if (other.p_r != first.p_r || other.p != first.p) {
    throw std::invalid_argument(fmt::format("{}: pole pairs p_r = {}, p = {} differ from {}'s p_r = {}, p = {}: "
                                            "pooled or merged runs are of one bench",
                                            name, other.p_r, other.p, first_name, first.p_r, first.p));
  }
  const auto differs = [&](bool a, bool b, const char* what) {
    if (a == b) return;
    throw std::invalid_argument(fmt::format(
        "{} {} {} but {} {}: pooled or merged runs need the same signals in every log (fit them apart, or pool "
        "the logs that share a layout)",
        name, b ? "has" : "lacks", what, first_name, a ? "has it" : "does not"));
  };
  differs(first.reference, other.reference, "a reference angle");
  differs(first.reference_aligned, other.reference_aligned, "an aligned reference ([bench] reference_aligned)");
  differs(first.rd, other.rd, "an R/D angle");
  differs(first.sincos, other.sincos, "sin/cos envelopes");
  differs(first.currents, other.currents, "phase currents");
}

}  // namespace resolver
