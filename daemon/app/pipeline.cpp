#include "daemon/app/pipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "daemon/app/embedded_dbc.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/service/calibration_store.h"

namespace resolver {

std::shared_ptr<const FrameDecoder> make_frame_decoder(const DaemonConfig& config) {
  const std::string path = config.dbc_path.empty() ? default_dbc_path() : config.dbc_path;
  // A DBC that does not parse throws InputError (kUsage) naming its file and line.
  auto db = std::make_shared<const dbc::Database>(config.dbc_path.empty() ? dbc::parse_dbc(embedded_bench_dbc(), path)
                                                                          : dbc::load_dbc_file(path));
  // A signal map that does not fit it throws InputError (kUsage) naming the config and the DBC.
  return std::make_shared<const FrameDecoder>(db, config.signal_map, Where::at_file(config.source));
}

SampleStreamConfig sample_stream_config(const DaemonConfig& config, const SampleSlice& slice) {
  SampleStreamConfig c;
  c.clock.counter_time = config.bench.time_from_counter;
  c.clock.sample_rate_hz = config.bench.sample_rate_hz;
  c.clock.max_counter_delta = config.max_counter_delta;
  c.use_bench_info = config.bench.use_bench_info;
  c.row_rate_hz = config.csv.map.row_rate_hz;
  c.slice = slice;
  return c;
}

std::string describe_layout(const DaemonConfig& config, const FrameDecoder& decoder) {
  if (config.dbc_path.empty() && config.source.empty()) {
    return "the default bench layout (" + default_dbc_path() + ": " + decoder.describe_layout() + ")";
  }
  return "the layout of " + (config.dbc_path.empty() ? default_dbc_path() : config.dbc_path) + " as " +
         (config.source.empty() ? std::string("the built-in config") : config.source) + " maps it (" +
         decoder.describe_layout() + ")";
}

namespace {

/// Every property of a signal that changes what a frame decodes to.
std::string signal_key(const dbc::Signal* sig) {
  if (sig == nullptr) return "-";
  return fmt::format("{}@{}+{}{}{}*{:.17g}+{:.17g}:{}", sig->name, sig->start_bit, sig->length,
                     sig->order == dbc::ByteOrder::kLittleEndian ? "le" : "be", sig->is_signed ? "s" : "u", sig->factor,
                     sig->offset, static_cast<int>(sig->value_type));
}

}  // namespace

LayoutIdentity layout_identity(const DaemonConfig& config) { return layout_identity(config, *make_frame_decoder(config)); }

LayoutIdentity layout_identity(const DaemonConfig& config, const FrameDecoder& decoder) {
  // What decodes a frame into a sample, and nothing else (comments, receivers, value
  // tables and the DBC's file name do not make another layout).
  std::string canonical = decoder.has_counter() ? "counter" : "no counter";
  for (const FrameDecoder::Slot& slot : decoder.slots()) {
    canonical += fmt::format("\n{} {:x}{} dlc {} counter {} crc {}", slot.message->name, slot.message->id,
                             slot.message->extended ? "x" : "", slot.message->dlc, signal_key(slot.counter),
                             signal_key(slot.crc));
    for (const FrameDecoder::RoleSignal& r : slot.roles) {
      canonical += fmt::format("\n  {} = {} to_unit {:.17g}{}", role_name(r.role), signal_key(r.signal), r.to_role_unit,
                               r.wrap ? " wrapped" : "");
    }
  }
  return {fmt::format("{:08x}", crc32_ieee(canonical)), describe_layout(config, decoder)};
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kHealthPeriodUs = 1'000'000;  // docs/ARCHITECTURE.md §4: health_t at 1 Hz

ProcessorConfig processor_config(const DaemonConfig& c) {
  ProcessorConfig p;
  p.p_r = c.bench.p_r;
  p.p = c.bench.p;
  p.hwang = c.hwang;
  p.compensate = c.compensation_enabled;
  p.method = c.method;
  p.domain = c.compensation_domain;
  p.sincos = c.sincos;
  p.fourier = c.fourier;
  p.ripple_revolutions = c.ripple_revolutions;
  return p;
}

void copy3(double (&dst)[3], const std::array<double, 3>& src, bool valid) {
  for (std::size_t k = 0; k < 3; ++k) dst[k] = valid ? src[k] : kNaN;
}

}  // namespace

Pipeline::Pipeline(const DaemonConfig& config, OutputSink& sink, std::ostream& diagnostics, bool realtime,
                   const SampleSlice& slice)
    : config_(config),
      sink_(sink),
      diagnostics_(diagnostics),
      realtime_(realtime),
      problems_(diagnostics, "resolverd: "),
      stream_(make_frame_decoder(config), sample_stream_config(config, slice),
              SampleStream::Callbacks{
                  [this](const Sample& s, std::uint8_t counter) { on_sample(s, counter); },
                  [this](const BenchInfo& i) { on_bench_info(i); },
                  [this](std::string_view reason, const std::string& msg) { problems_.report(reason, msg); }}),
      processor_(processor_config(config)),
      model_fit_(config.model.enabled ? std::make_unique<LiveModelFit>(config.model, sink, diagnostics, realtime)
                                      : nullptr),
      signal_health_(health_config_for(config, stream_.intake().decoder()), config.bench.p_r, config.bench.sample_rate_hz,
                     diagnostics) {
  // Once per load: the DBC's own findings ("file.dbc:40: ...": skipped keywords, comments on
  // unknown signals), then the decoder's (overlaps among signals it does not read).
  for (const std::string& w : stream_.intake().decoder().database().warnings) {
    diagnostics << "resolverd: warning: " << w << "\n";
  }
  for (const std::string& w : stream_.intake().decoder().warnings()) diagnostics << "resolverd: warning: " << w << "\n";
}

namespace {

bool same_model_spec(const ModelFitOptions& a, const ModelFitOptions& b) {
  if (a.effects != b.effects || a.custom.size() != b.custom.size()) return false;
  for (std::size_t i = 0; i < a.custom.size(); ++i) {
    const CustomEffectSpec& x = a.custom[i];
    const CustomEffectSpec& y = b.custom[i];
    if (x.name != y.name || x.signal != y.signal || x.terms != y.terms) return false;
  }
  return true;
}

bool same_fit_options(const ModelFitOptions& a, const ModelFitOptions& b) {
  return a.enabled == b.enabled && same_model_spec(a, b) && a.window_revolutions == b.window_revolutions &&
         a.candidates == b.candidates && a.reference_aligned == b.reference_aligned;
}

bool same_stream(const SampleStreamConfig& a, const SampleStreamConfig& b) {
  return a.clock.counter_time == b.clock.counter_time && a.clock.sample_rate_hz == b.clock.sample_rate_hz &&
         a.clock.max_counter_delta == b.clock.max_counter_delta && a.use_bench_info == b.use_bench_info &&
         a.row_rate_hz == b.row_rate_hz;
}

}  // namespace

const Pipeline::Reload& Pipeline::reload(const DaemonConfig& fresh) {
  // Everything that can fail first: nothing below changes until these are built.
  std::shared_ptr<const FrameDecoder> decoder = make_frame_decoder(fresh);
  const bool same_layout = layout_identity(config_, stream_.intake().decoder()).id == layout_identity(fresh, *decoder).id;
  const SampleStreamConfig stream_config = sample_stream_config(fresh, stream_.slice());
  SignalHealthConfig health = health_config_for(fresh, *decoder);
  const ProcessorConfig now = processor_.config();
  ProcessorConfig next = processor_config(fresh);
  if (bench_info_seen_ && fresh.bench.use_bench_info) {  // the bench said so; the config's are defaults
    next.p_r = now.p_r;
    next.p = now.p;
  }
  const bool same_model = next.method == now.method && next.p_r == now.p_r && next.p == now.p &&
                          same_model_spec(config_.model, fresh.model);
  const bool keep_processor = same_model && next == now;
  std::optional<SampleProcessor> replacement;
  if (!keep_processor) replacement.emplace(next);
  const bool keep_fit = model_fit_ ? same_fit_options(config_.model, fresh.model) : !fresh.model.enabled;
  std::unique_ptr<LiveModelFit> fit;
  if (!keep_fit && fresh.model.enabled) fit = std::make_unique<LiveModelFit>(fresh.model, sink_, diagnostics_, realtime_);

  // Nothing below throws.
  std::vector<std::string> notes;
  if (!same_layout) {
    notes.push_back("new layout " + describe_layout(fresh, *decoder) + ": counters and joins restart");
    for (const std::string& w : decoder->warnings()) diagnostics_ << "resolverd: warning: " << w << "\n";
  }
  if (!same_layout || !same_stream(stream_config, sample_stream_config(config_, stream_.slice()))) {
    stream_.reconfigure(same_layout ? nullptr : decoder, stream_config);
  }
  if (rows_seen_ && !fresh.health_full_scale_set) {
    health.full_scale = csv_sincos_full_scale(fresh.csv.map);
    health.clip_margin = 0.0;
  }
  signal_health_.set_config(health);
  signal_health_.set_pole_pairs(next.p_r);
  if (!keep_fit) {
    if (model_fit_) {
      // Its last windows are fitted and published under the config they were read with.
      model_fit_->finish();
      adopt_live_fit();
      if (fit) fit->continue_from(*model_fit_);
    }
    model_fit_ = std::move(fit);
    notes.emplace_back(model_fit_ ? "the live model fit starts a new window" : "the live model fit is off");
  }
  bool estimate_kept = keep_processor;
  if (!keep_processor) {
    const ModelEstimate learned = processor_.estimate();
    if (same_model && next.method == EstimatorMethod::kModel && !processor_.model().empty()) {
      replacement->set_model(processor_.model(), learned.samples, learned.revolutions);
      estimate_kept = true;
    } else if (same_model && !processor_.model().empty()) {
      // An older method learns again; its last model compensates meanwhile.
      replacement->set_model(processor_.model(), learned.samples, learned.revolutions);
    }
    if (table_) replacement->set_table(*table_);
    std::string why = next.method != now.method     ? "the method changed (" + learned.method + " -> " +
                                                           replacement->estimate().method + ")"
                      : !same_model                 ? std::string("the model changed ([model] effects or custom "
                                                                  "effects, or pole pairs)")
                      : estimate_kept               ? std::string()
                      : learned.params.empty()      ? std::string("nothing was learned yet")
                                                    : std::string("the estimator's settings changed");
    processor_ = std::move(*replacement);
    notes.push_back(estimate_kept ? "the learned model is kept (the estimator's settings are new)"
                                  : "estimation restarts: " + why);
  } else {
    notes.emplace_back("the learned estimate is kept");
  }
  config_ = fresh;
  Reload r;
  r.t_s = have_t_ ? last_t_ - first_t_ : 0.0;
  r.sample_index = last_sample_index_;
  r.utime = last_utime_;
  r.estimate_kept = estimate_kept;
  for (std::size_t i = 0; i < notes.size(); ++i) r.what += (i ? "; " : "") + notes[i];
  reloads_.push_back(std::move(r));
  return reloads_.back();
}

void Pipeline::count_problem(std::string_view reason, const std::string& message) {
  stream_.count_problem(reason, message);
}

void Pipeline::advance_health_clock(std::int64_t now_us) {
  // The input's own clock stepping back (a log appended, a clock set) starts
  // the window again, so health keeps coming every second of input time; a
  // jump publishes once. Compared with the previous frame, not with the
  // window start: live, tick() starts windows on the wall clock, and frames
  // that waited in the socket are older than that without any step.
  const bool stepped_back = have_frame_time_ && now_us < last_frame_us_;
  have_frame_time_ = true;
  last_frame_us_ = now_us;
  if (health_window_start_us_ < 0 || stepped_back) health_window_start_us_ = now_us;
  if (now_us - health_window_start_us_ >= kHealthPeriodUs) publish_health(now_us);
}

void Pipeline::feed_untimed(const CanFrame& frame, std::uint64_t line) {
  const std::int64_t complete_before = stream_.intake().stats().samples_complete;
  stream_.feed(frame, line);
  // Only a sample completed by one of its own frames says which frame
  // completes samples; one emitted because a newer counter began (while the
  // joiner learns the layout, or with a frame missing) does not.
  if (stream_.intake().stats().samples_complete != complete_before &&
      stream_.intake().last_frame_counter() == last_counter_) {
    note_completing_frame(frame);
  }
  advance_health_clock(frame.timestamp_us);
}

void Pipeline::feed_row(const RowSample& row, std::uint64_t line) {
  if (!rows_seen_) {
    // A CSV's sin/cos have no DBC range: their full scale is the column's
    // full_scale, else unknown (health then judges levels relatively).
    rows_seen_ = true;
    if (!config_.health_full_scale_set) signal_health_.set_full_scale(csv_sincos_full_scale(config_.csv.map), 0.0);
  }
  stream_.feed_row(row, line);
  // Rows without a time column: health runs on row number / row rate.
  const double rate = config_.csv.map.row_rate_hz;
  advance_health_clock(row.has_time ? row.time_us
                                    : std::llround(static_cast<double>(row.sequence) * 1e6 / (rate > 0.0 ? rate : 1.0)));
}

void Pipeline::feed(const CanFrame& frame, std::uint64_t line, Clock::time_point arrival) {
  feed_untimed(frame, line);
  const double us = std::chrono::duration<double, std::micro>(Clock::now() - arrival).count();
  latency_window_.add(us);
  latency_total_.add(us);
}

void Pipeline::note_completing_frame(const CanFrame& frame) {
  completing_frames_.add(frame.id);
  if (wake_ids_.empty() || std::find(wake_ids_.begin(), wake_ids_.end(), frame.id) != wake_ids_.end()) return;
  // The frame came through the quiet socket, so the sample waited for the
  // next waking frame: the latency is a sample period or the read timeout.
  stream_.count_problem("completed_by_quiet_frame",
                        fmt::format("a sample was completed by frame 0x{:X}, which does not wake the reader "
                                    "([can] wake_ids), so it waited for the next wake-up; with wake_ids = \"auto\" "
                                    "resolverd goes back to every frame if this repeats, with a fixed list name the "
                                    "frame the run report says completes the samples",
                                    frame.id));
}

void Pipeline::tick(std::int64_t now_us) {
  if (health_window_start_us_ < 0) {
    health_window_start_us_ = now_us;
    return;
  }
  if (now_us - health_window_start_us_ >= kHealthPeriodUs) publish_health(now_us);
}

bool Pipeline::adopt_live_fit() {
  bool adopted = false;
  // Every window fitted since the last call, oldest first (finish() may leave two).
  while (auto fitted = model_fit_->take_model()) {
    // With an older method the live fit is a diagnostic (model_fit_t): the method's
    // own estimate compensates.
    if (processor_.config().method != EstimatorMethod::kModel) continue;
    run_estimate_.add(fitted->model, fitted->samples, fitted->revolutions);
    processor_.set_model(std::move(fitted->model), fitted->samples, fitted->revolutions);
    adopted = true;
  }
  return adopted;
}

void Pipeline::finish() {
  stream_.flush();
  if (model_fit_) {
    model_fit_->finish();
    bool fresh = adopt_live_fit();
    // The run's estimate is every window's, combined; compensation is over (no
    // sample follows), so the processor now holds it for the report, the last
    // estimate_t and the calibration.
    if (processor_.config().method == EstimatorMethod::kModel && run_estimate_.windows() > 1) {
      processor_.set_model(run_estimate_.combined(), run_estimate_.samples(), run_estimate_.revolutions());
      fresh = true;
    }
    if (fresh) {
      // No sample follows to carry it: publish the final estimate now.
      Sample last;
      last.utime = last_utime_;
      last.index = last_sample_index_;
      publish_estimate(last, last_counter_);
    }
  }
  signal_health_.finish();
  publish_health(last_frame_us_);
}

void Pipeline::on_bench_info(const BenchInfo& info) {
  if (!config_.bench.use_bench_info) return;
  const ProcessorConfig& pc = processor_.config();
  if (info.p_r < 1 || info.p < 1) {
    problems_.report("bench_info_invalid", "BENCH_INFO with p_r=" + std::to_string(info.p_r) +
                                               ", p=" + std::to_string(info.p) + " ignored (pole pairs must be >= 1)");
    return;
  }
  if (info.sample_rate_hz > 0.0) signal_health_.set_sample_rate(info.sample_rate_hz);
  if (info.p_r != pc.p_r || info.p != pc.p) {
    if (bench_info_seen_ || samples_ > 0) {
      problems_.report("bench_info_changed", "BENCH_INFO changed pole pairs to p_r=" + std::to_string(info.p_r) +
                                                 ", p=" + std::to_string(info.p) + ": estimation restarts");
    }
    processor_.set_pole_pairs(info.p_r, info.p);
    signal_health_.set_pole_pairs(info.p_r);
  }
  bench_info_seen_ = true;
}

void Pipeline::on_sample(const Sample& sample, std::uint8_t counter) {
  ++samples_;
  if (!have_t_) first_t_ = sample.t;
  have_t_ = true;
  last_t_ = sample.t;
  last_sample_index_ = sample.index;
  last_counter_ = counter;
  last_utime_ = sample.utime;
  if (observer_) observer_(sample);
  const SampleOutput out = processor_.process(sample);
  signal_health_.add(sample);
  if (model_fit_) {
    const ProcessorConfig& pc = processor_.config();
    // The faults this sample is under: a window mostly under one is never "explained".
    model_fit_->add(sample, pc.p_r, pc.p, {sample.utime, sample.index, counter},
                    signal_health_.monitor().last_sample_faults());
    adopt_live_fit();
  }
  summary_.add(out, processor_, sample.t);
  if (!out.has_angle) return;

  const bool angle_due = sample.index % config_.angle_decimation == 0;
  if (angle_due) {
    angle_t a;
    a.utime = sample.utime;
    a.sample_index = sample.index;
    a.counter = counter;
    a.theta_rd = out.theta_rd;
    // No amplitude, no angle: atan2 of noise published as an angle would be believed.
    a.theta_sincos = signal_health_.sincos_lost(sample) ? kNaN : out.theta_sincos;
    a.theta_comp = out.theta_comp;
    a.theta_ref = out.theta_ref;
    a.speed_mech_rad_s = out.speed_mech;
    a.eps_hat = out.eps_hat;
    a.eps_ref = out.eps_ref;
    sink_.publish(a);
  }
  if (out.has_dq && sample.index % config_.dq_decimation == 0) {
    const RippleSet& r = processor_.ripple();
    dq_t d;
    d.utime = sample.utime;
    d.sample_index = sample.index;
    d.counter = counter;
    d.electrical_freq_hz = out.electrical_freq_hz;
    d.i_d_raw = out.i_d_raw;
    d.i_q_raw = out.i_q_raw;
    d.i_d_comp = out.i_d_comp;
    d.i_q_comp = out.i_q_comp;
    d.i_d_ref = out.i_d_ref;
    d.i_q_ref = out.i_q_ref;
    for (std::size_t k = 0; k < 3; ++k) d.ripple_order[k] = static_cast<int16_t>(kRippleOrders[k]);
    copy3(d.i_d_ripple_raw, r.raw.d, r.raw_valid);
    copy3(d.i_q_ripple_raw, r.raw.q, r.raw_valid);
    copy3(d.i_d_ripple_comp, r.comp.d, r.comp_valid);
    copy3(d.i_q_ripple_comp, r.comp.q, r.comp_valid);
    copy3(d.i_d_ripple_ref, r.ref.d, r.ref_valid);
    copy3(d.i_q_ripple_ref, r.ref.q, r.ref_valid);
    d.ripple_valid = r.raw_valid;
    sink_.publish(d);
  }
  if (out.estimate_updated) publish_estimate(sample, counter);
}

void Pipeline::publish_estimate(const Sample& sample, std::uint8_t counter) {
  const ModelEstimate est = processor_.estimate();
  estimate_t e;
  e.utime = sample.utime;
  e.sample_index = sample.index;
  e.counter = counter;
  e.method = est.method;
  for (const ModelParameter& p : est.params) {
    e.param_name.push_back(p.name);
    e.value.push_back(p.value);
    e.std_error.push_back(p.std_error);
  }
  e.num_params = static_cast<int32_t>(est.params.size());
  e.samples_used = est.samples;
  e.revolutions_used = est.revolutions;
  e.converged = est.converged;
  sink_.publish(e);
}

void Pipeline::publish_health(std::int64_t utime) {
  const IntakeStats& st = stream_.intake().stats();
  health_t h;
  h.utime = utime;
  h.sample_index = last_sample_index_;
  h.counter = last_counter_;
  h.frames_seen = st.frames_seen;
  h.frames_decoded = st.frames_decoded;
  for (const auto& [reason, count] : stream_.intake().rejects().all()) {
    h.reject_reason.push_back(reason);
    h.reject_count.push_back(count);
  }
  h.num_reasons = static_cast<int32_t>(h.reject_reason.size());
  h.samples_complete = st.samples_complete;
  h.samples_incomplete = st.samples_incomplete;
  h.bus_errors = st.bus_errors;
  h.kernel_drops = kernel_drops_;
  const double window_s = static_cast<double>(utime - health_window_start_us_) * 1e-6;
  h.frame_rate_hz = window_s > 0.0 ? static_cast<double>(st.frames_seen - frames_at_window_start_) / window_s : 0.0;
  h.latency_p50_us = latency_window_.percentile(0.50);
  h.latency_p99_us = latency_window_.percentile(0.99);
  h.latency_max_us = latency_window_.max();
  signal_health_.fill(h);
  sink_.publish(h);
  latency_window_.clear();
  health_window_start_us_ = utime;
  frames_at_window_start_ = st.frames_seen;
}

}  // namespace resolver
