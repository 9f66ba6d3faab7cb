#include "daemon/app/live_model_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Samples between checks whether the running fit is done (a future's status
/// check takes a lock; once per 64 samples is ~30 ms at 2 kHz).
constexpr std::uint32_t kPollEvery = 64;
/// The fit needs two revolutions (model_discovery.h); a shorter tail is not fitted.
constexpr double kMinTailRevolutions = 2.0;
/// At most this many windows in a row start warm (header): a safety net for a valley that
/// moved with the operating point held (every 8th window started cold before; a cold
/// window of a tracking-loop model costs ~8 warm ones: its five omega_n starts).
constexpr std::int64_t kColdEvery = 32;
/// A speed this share of another's away (or the other way) is another operating point: the
/// valleys of a loop's omega_n and of a delay's phase sit where the ripple's frequencies
/// (whole multiples of the speed) meet the loop's response and wrap the delay's phase, so
/// a speed step moves them; a play's take-up flips with direction.
constexpr double kSpeedMoved = 0.1;

/// Where the next window's fit starts: this one's converged model and the candidates it
/// refitted to convergence, all settled. Linearised candidates are one step from
/// neutral, not a fit: they start again from their defaults. A model fit that did
/// not converge is no start: the next window starts cold.
FitStartValues start_after(const Explanation& ex) {
  FitStartValues s;
  if (!ex.fit.converged) return s;
  s.values = ex.fit.model.parameters();
  s.settled = ex.fit.effects;
  for (const Candidate& c : ex.candidates) {
    if (!c.refitted) continue;
    s.values.insert(s.values.end(), c.params.begin(), c.params.end());
    s.settled.push_back(c.effect);
  }
  return s;
}

}  // namespace

bool operating_point_held(double last_speed, double speed) {
  if (!std::isfinite(last_speed) || !std::isfinite(speed)) return false;
  return std::abs(speed - last_speed) <= kSpeedMoved * std::max(std::abs(speed), std::abs(last_speed));
}

bool settled_at_a_new_operating_point(double cold_speed, double previous_speed, double speed) {
  return !operating_point_held(cold_speed, speed) && operating_point_held(previous_speed, speed);
}

model_fit_t make_model_fit_message(const Explanation* ex, bool candidates, const std::vector<std::string>& effects) {
  model_fit_t m{};
  m.effects = effects;
  m.num_effects = static_cast<std::int32_t>(m.effects.size());
  if (ex == nullptr) {
    m.residual_rms_rad = kNaN;
    m.noise_floor_rad = kNaN;
    m.verdict = "insufficient_data";
    return m;
  }
  m.residual_rms_rad = ex->fit.residual_rms_rad;
  m.noise_floor_rad = ex->fit.noise_floor_rad;
  m.reason = ex->summary;
  m.samples_fitted = ex->fit.account.fitted;
  m.samples_window = ex->fit.account.samples_in;
  for (const auto& h : ex->fit.harmonics) {
    m.harmonic_order.push_back(static_cast<std::int16_t>(h.order));
    m.residual_by_harmonic_rad.push_back(h.amplitude);
  }
  m.num_harmonics = static_cast<std::int32_t>(m.harmonic_order.size());
  for (const auto& c : ex->candidates) {
    m.candidate_effect.push_back(c.effect);
    m.candidate_residual_rad.push_back(c.residual_after_rad);
    m.candidate_reason.push_back(c.reason);
  }
  m.num_candidates = static_cast<std::int32_t>(m.candidate_effect.size());
  if (candidates) m.verdict = std::string(to_string(ex->verdict));
  else m.verdict = ex->fit.explained ? "explained" : "unexplained";  // no candidates ranked: nothing is named
  return m;
}

LiveModelFit::LiveModelFit(const ModelFitOptions& options, OutputSink& sink, std::ostream& diagnostics, bool realtime)
    : options_(options),
      sink_(sink),
      diagnostics_(diagnostics),
      realtime_(realtime),
      window_(ModelWindowConfig{options.window_revolutions}) {}

LiveModelFit::~LiveModelFit() {
  // A running fit holds no reference to this object, but its thread must end
  // before the process does; the result is dropped (finish() publishes it).
  if (running_.valid()) running_.wait();
}

std::vector<std::string> LiveModelFit::take_window_faults() {
  std::vector<std::string> out = lasting_faults(window_faults_, window_samples_, kUntrustedFaultShare);
  window_faults_ = {};
  window_samples_ = 0;
  return out;
}

void LiveModelFit::add(const Sample& sample, int p_r, int p, const Stamp& stamp, std::uint8_t active_faults) {
  last_stamp_ = stamp;
  ++window_samples_;
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) window_faults_[i] += (active_faults >> i) & 1U;
  if (window_.add(sample, p_r, p)) {
    const double speed = window_.mean_speed();
    DiscoveryInput w = window_.take();
    std::vector<std::string> untrusted = take_window_faults();
    if (running_.valid()) {
      if (realtime_ && running_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
        ++counters_.windows_skipped;
        return;
      }
      publish_ready(true);
    }
    start(std::move(w), speed, stamp, std::move(untrusted));
    return;
  }
  // Live, a finished fit is published (and its model compensates) as soon as a poll sees
  // it. A replay publishes it only where the next window completes or the input ends: a
  // poll there would hand the model over at whichever sample the fit happened to finish
  // by, and the compensated samples (and the report's compensated RMS) would depend on
  // the machine's load (an ASC and a candump copy of one log differed by 1e-9 rad in
  // compensated RMS under ctest -j2).
  if (realtime_ && ++since_poll_ >= kPollEvery) {
    since_poll_ = 0;
    publish_ready(false);
  }
}

void LiveModelFit::finish() {
  publish_ready(true);
  if (window_.revolutions() >= kMinTailRevolutions) {
    const double speed = window_.mean_speed();
    start(window_.take(), speed, last_stamp_, take_window_faults());
    publish_ready(true);
  } else if (window_.size() > 0 && counters_.windows_fitted + counters_.windows_insufficient == 0) {
    // Nothing was published in the whole run (a stopped motor): say so, with the reason.
    model_fit_t m = make_model_fit_message(nullptr, options_.candidates, options_.effects);
    m.reason = "the rotor turned " + std::to_string(window_.revolutions()) +
               " resolver revolutions in the whole run: a stopped motor, nothing to fit";
    m.samples_window = static_cast<std::int64_t>(window_.size());
    m.utime = last_stamp_.utime;
    m.sample_index = last_stamp_.sample_index;
    m.counter = last_stamp_.counter;
    ++counters_.windows_insufficient;
    diagnostics_ << "resolverd: model fit: the rotor turned " << window_.revolutions()
                 << " resolver revolutions in the whole run (stopped?): model_fit_t verdict insufficient_data\n";
    sink_.publish(m);
    last_ = std::move(m);
  }
}

void LiveModelFit::start(DiscoveryInput window, double speed, const Stamp& stamp, std::vector<std::string> untrusted) {
  const ModelFitOptions opt = options_;
  const bool warm = !warm_start_.values.empty() && warm_in_a_row_ + 1 < kColdEvery &&
                    !settled_at_a_new_operating_point(cold_speed_, previous_speed_, speed);
  warm_in_a_row_ = warm ? warm_in_a_row_ + 1 : 0;
  if (!warm) cold_speed_ = speed;
  previous_speed_ = speed;
  FitStartValues from = warm ? warm_start_ : FitStartValues{};
  running_ = std::async(std::launch::async, [opt, stamp, w = std::move(window), untrusted = std::move(untrusted),
                                             from = std::move(from)]() {
    Result r;
    model_fit_t& m = r.message;
    try {
      DiscoveryOptions dopt;
      dopt.customs = opt.customs.get();
      dopt.prepare.reference_aligned = opt.reference_aligned;
      dopt.rank_when_explained = false;  // see DiscoveryOptions: the costly part, moot while explained
      dopt.untrusted_input = untrusted;
      dopt.start = from;
      Explanation ex;
      if (opt.candidates) ex = explain_model(w, opt.effects, dopt);
      else ex.fit = fit_model(w, opt.effects, dopt);
      r.next_start = start_after(ex);
      m = make_model_fit_message(&ex, opt.candidates, opt.effects);
      r.fitted = FittedModel{ex.fit.model, ex.fit.account.fitted, ex.fit.account.revolutions_electrical,
                             std_error_basis(ex.fit)};
      r.fitted->model.keep(opt.customs);
    } catch (const std::exception& e) {
      // Too few revolutions, no R/D angle, no currents for a current-side effect:
      // the window says so in its verdict instead of disappearing.
      m = make_model_fit_message(nullptr, opt.candidates, opt.effects);
      m.reason = e.what();
      m.samples_window = static_cast<std::int64_t>(w.samples.size());
      r.error = e.what();
    }
    m.utime = stamp.utime;
    m.sample_index = stamp.sample_index;
    m.counter = stamp.counter;
    return r;
  });
}

void LiveModelFit::publish_ready(bool wait) {
  if (!running_.valid()) return;
  if (!wait && running_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  Result r = running_.get();
  if (r.error.empty()) {
    ++counters_.windows_fitted;
  } else {
    ++counters_.windows_insufficient;
    if (r.error != last_error_) {
      diagnostics_ << "resolverd: model fit: window ending at sample " << r.message.sample_index
                   << " not fitted (model_fit_t verdict insufficient_data): " << r.error << "\n";
    }
  }
  last_error_ = r.error;
  warm_start_ = std::move(r.next_start);  // a window that could not be fitted leaves the next one cold
  if (r.fitted) pending_models_.push_back(std::move(*r.fitted));
  sink_.publish(r.message);
  last_ = std::move(r.message);
}

std::optional<LiveModelFit::FittedModel> LiveModelFit::take_model() {
  if (pending_models_.empty()) return std::nullopt;
  std::optional<FittedModel> out = std::move(pending_models_.front());
  pending_models_.pop_front();
  taken_std_error_basis_ = out->std_error_basis;
  return out;
}

}  // namespace resolver
