// Micro-benchmarks of resolverd's per-frame and per-sample hot paths.
//
// Each benchmark runs one stage of the chain in pipeline.h over a synthetic
// but realistic stream of the default bench (docs/ARCHITECTURE.md §4): 2 kHz control rate,
// 200 r/min, p_r = p = 3, 16-bit R/D angle, amplitude imbalance alpha = 0.003,
// 10 A of i_q, a reference encoder, and BENCH_INFO at 10 Hz. So one control
// period is three frames (0x100, 0x101, 0x102) and one resolver electrical
// revolution is 200 samples.
//
//   BM_ParseCandumpLine     one candump -l line -> CanFrame          [lines/s]
//   BM_DbcDecodePhysical    one DBC signal -> physical value         [signals/s]
//   BM_DbcDecodeMessage     every signal of RESOLVER_SAMPLE          [messages/s]
//   BM_FrameDecoder         ID/DLC/CRC checks + role extraction      [frames/s]
//   BM_FrameIntake          decode + counters + join into samples    [frames/s]
//   BM_HwangUpdate          HwangIntegralEstimator::update           [samples/s]
//   BM_SinCosLsReference    SinCosLeastSquares::add with reference   [samples/s]
//                           (alpha, beta, offsets, K_3; docs/ARCHITECTURE.md §7)
//   BM_SinCosLsConic        SinCosLeastSquares::add, conic only      [samples/s]
//   BM_AngleFourierUpdate   AngleErrorFourier::add, orders 1..4      [samples/s]
//   BM_CompensateAngle      eps_hat(theta_rd) from a Fourier fit     [samples/s]
//   BM_CompensateSinCos     corrected_angle: sin/cos corrected, atan2 [samples/s]
//   BM_SampleProcessor      SampleProcessor::process                 [samples/s]
//   BM_DqTransform          Clarke + one Park (cos/sin included)     [samples/s]
//   BM_PipelineNullSink     Pipeline::feed, messages built, not sent [frames/s]
//                           ([model] enabled = false, as the replay benchmark)
//   BM_PipelineModelFit     the same with the live model fit         [frames/s]
//   BM_PipelineLcmFile      Pipeline::feed into LCM file:// (what    [frames/s]
//                           `resolverd --replay --lcm file://` does, minus log reading)
//   BM_DesignPass/0         one pass of the exact model over a       [rows/s]
//                           prepared log's rows into its normal equations (least_squares.h
//                           accumulate): the model amplitude_imbalance and its nuisances
//   BM_DesignPass/1         the same with every candidate's columns  [rows/s]
//                           (a statistics pass, the candidates' ranking). Every Gauss-
//                           Newton pass of discovery costs one such pass (issue 23's floor)
//
// Run: build/bin/bench_hot_paths --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
// The "items_per_second" column is the throughput named on the right above.
// Not registered with ctest except a one-iteration smoke run (label bench-smoke).
#include <benchmark/benchmark.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <span>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/app/lcm_output.h"
#include "daemon/app/output_sink.h"
#include "daemon/app/pipeline.h"
#include "daemon/core/angles.h"
#include "daemon/core/discovery/fit_support.h"
#include "daemon/core/discovery/prepare.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/least_squares.h"
#include "daemon/core/model/normal_equations.h"
#include "daemon/core/estimation/dq_transform.h"
#include "daemon/core/estimation/angle_error_fourier.h"
#include "daemon/core/estimation/hwang_integral.h"
#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "daemon/core/estimation/sample_processor.h"
#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/bench_layout.h"
#include "daemon/decode/frame_decoder.h"
#include "daemon/decode/frame_intake.h"
#include "daemon/decode/signal_map.h"
#include "drivers/can_frame.h"
#include "drivers/candump/candump_line.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc (set by tests/bench/CMakeLists.txt)"
#endif

namespace {

using resolver::CanFrame;

// ---------------------------------------------------------------------------
// The synthetic bench stream.

constexpr double kSampleRateHz = 2000.0;  // resolver-sim's default control rate [Hz]
constexpr double kRpm = 200.0;            // Hwang's test speed [r/min]
constexpr int kPr = 3;                    // resolver pole pairs
constexpr int kP = 3;                     // motor pole pairs
constexpr double kAlpha = 0.003;          // amplitude imbalance (cos gain 1 + alpha) [-]
constexpr double kAmplitude = 26000.0;    // sin/cos envelope [ADC counts] (resolver-sim default)
constexpr double kIq = 10.0;              // q current [A]
// One mechanical revolution at 200 r/min and 2 kHz is 600 samples; the u8
// counter repeats every 256. 19200 periods = lcm(600, 256): the stream can be
// replayed in a loop with continuous counters and angles.
constexpr std::size_t kPeriods = 19200;
constexpr std::size_t kSamplesPerMechRev = 600;
constexpr std::size_t kBenchInfoEvery = 200;  // periods between BENCH_INFO frames (10 Hz)
constexpr double kDt = 1.0 / kSampleRateHz;   // [s]
constexpr std::int64_t kDtUs = 500;           // [us]

/// Physical values of one control period, from a small independent model.
struct TruthSample {
  double theta_rd = 0.0;     // [rad] R/D angle, 16-bit quantized
  double sin = 0.0, cos = 0.0;  // [counts]
  double i_a = 0.0, i_b = 0.0, i_c = 0.0;  // [A]
  double theta_m = 0.0;      // [rad] true mechanical angle
};

TruthSample truth_at(std::size_t k) {
  const double omega_m = kRpm * 2.0 * std::numbers::pi / 60.0;  // [rad/s]
  const double theta_m = std::fmod(omega_m * static_cast<double>(k) * kDt, 2.0 * std::numbers::pi);
  const double theta = kPr * theta_m;
  // eps = theta - phi ~ (alpha/2) sin(2 theta) (Hwang eq. 10), so phi = theta - eps.
  const double phi = resolver::wrap_2pi(theta - 0.5 * kAlpha * std::sin(2.0 * theta));
  TruthSample s;
  s.theta_rd = std::floor(phi / (2.0 * std::numbers::pi) * 65536.0) * (2.0 * std::numbers::pi / 65536.0);
  s.sin = std::round(kAmplitude * std::sin(theta));
  s.cos = std::round(kAmplitude * (1.0 + kAlpha) * std::cos(theta));
  const double theta_e = kP * theta_m;
  const double i_alpha = -kIq * std::sin(theta_e);  // inverse Park with i_d = 0
  const double i_beta = kIq * std::cos(theta_e);
  s.i_a = std::round(i_alpha * 1000.0) / 1000.0;
  s.i_b = std::round((-0.5 * i_alpha + 0.5 * std::numbers::sqrt3 * i_beta) * 1000.0) / 1000.0;
  s.i_c = std::round((-0.5 * i_alpha - 0.5 * std::numbers::sqrt3 * i_beta) * 1000.0) / 1000.0;
  s.theta_m = theta_m;
  return s;
}

std::int16_t to_i16(double v) { return static_cast<std::int16_t>(std::lround(v)); }

/// Frames of kPeriods control periods, in the order the inverter sends them.
const std::vector<CanFrame>& bench_frames() {
  static const std::vector<CanFrame> frames = [] {
    namespace b = resolver::bench;
    std::vector<CanFrame> out;
    out.reserve(kPeriods * 3 + kPeriods / kBenchInfoEvery);
    const std::int64_t t0_us = 1'700'000'000'000'000;
    for (std::size_t k = 0; k < kPeriods; ++k) {
      const TruthSample s = truth_at(k);
      const std::int64_t t_us = t0_us + static_cast<std::int64_t>(k) * kDtUs;
      const auto counter = static_cast<std::uint8_t>(k & 0xFFU);
      if (k % kBenchInfoEvery == 0) {
        out.push_back(b::encode_bench_info(t_us, kPr, kP, 16, static_cast<std::uint16_t>(kSampleRateHz)));
      }
      const auto rd_counts = static_cast<std::uint16_t>(std::lround(s.theta_rd / (2.0 * std::numbers::pi) * 65536.0) & 0xFFFF);
      out.push_back(b::encode_resolver_sample(t_us, counter, to_i16(s.sin), to_i16(s.cos), rd_counts));
      out.push_back(b::encode_phase_currents(t_us, counter, to_i16(s.i_a * 1000.0), to_i16(s.i_b * 1000.0),
                                             to_i16(s.i_c * 1000.0)));
      const auto ref_counts =
          static_cast<std::uint32_t>(std::llround(s.theta_m / (2.0 * std::numbers::pi) * 4294967296.0) & 0xFFFFFFFFLL);
      out.push_back(b::encode_reference_angle(t_us, counter, ref_counts));
    }
    for (CanFrame& f : out) f.set_iface("can0");
    return out;
  }();
  return frames;
}

/// The same frames as candump -l lines ("(1700000000.000000) can0 100#...").
struct CandumpText {
  std::string text;
  std::vector<std::string_view> lines;
};

const CandumpText& bench_lines() {
  static const CandumpText log = [] {
    CandumpText t;
    const auto& frames = bench_frames();
    t.text.reserve(frames.size() * 48);
    std::vector<std::size_t> ends;
    ends.reserve(frames.size());
    for (const CanFrame& f : frames) {
      resolver::append_candump_line(f, t.text);
      ends.push_back(t.text.size());
    }
    std::size_t begin = 0;
    for (std::size_t end : ends) {
      t.lines.emplace_back(t.text.data() + begin, end - begin);
      begin = end;
    }
    return t;
  }();
  return log;
}

/// Control period k as a joined sample with every signal (t from the period).
resolver::Sample sample_at(std::size_t k) {
  const TruthSample s = truth_at(k);
  resolver::Sample x;
  x.t = static_cast<double>(k) * kDt;
  x.has_rd = true;
  x.theta_rd = s.theta_rd;
  x.has_sincos = true;
  x.sin = s.sin;
  x.cos = s.cos;
  x.has_currents = true;
  x.i_a = s.i_a;
  x.i_b = s.i_b;
  x.i_c = s.i_c;
  x.has_ref = true;
  x.theta_m_ref = s.theta_m;
  return x;
}

/// SampleInput per control period (the input of SampleProcessor).
const std::vector<resolver::SampleInput>& bench_inputs() {
  static const std::vector<resolver::SampleInput> inputs = [] {
    std::vector<resolver::SampleInput> out;
    out.reserve(kSamplesPerMechRev);
    for (std::size_t k = 0; k < kSamplesPerMechRev; ++k) out.push_back(sample_at(k));
    return out;
  }();
  return inputs;
}

std::shared_ptr<const resolver::dbc::Database> bench_dbc() {
  static const std::shared_ptr<const resolver::dbc::Database> db = [] {
    // A failure throws InputError or IoError naming the file.
    return std::make_shared<const resolver::dbc::Database>(resolver::dbc::load_dbc_file(RESOLVER_BENCH_DBC));
  }();
  return db;
}

/// An ostream that discards everything (the pipeline's diagnostics).
class NullBuffer final : public std::streambuf {
 protected:
  int_type overflow(int_type c) override { return traits_type::not_eof(c); }
  std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
};

/// Counts messages and keeps the last values alive, publishes nothing.
class NullSink final : public resolver::OutputSink {
 public:
  void publish(const resolver::angle_t& msg) override { note(msg.theta_comp); }
  void publish(const resolver::dq_t& msg) override { note(msg.i_d_comp); }
  void publish(const resolver::estimate_t& msg) override { note(static_cast<double>(msg.utime)); }
  void publish(const resolver::model_fit_t& msg) override { note(static_cast<double>(msg.utime)); }
  void publish(const resolver::health_t& msg) override { note(static_cast<double>(msg.utime)); }
  std::int64_t messages = 0;

 private:
  void note(double v) {
    ++messages;
    benchmark::DoNotOptimize(v);
  }
};

// ---------------------------------------------------------------------------
// Benchmarks.

void BM_ParseCandumpLine(benchmark::State& state) {
  const auto& lines = bench_lines().lines;
  CanFrame frame;
  std::size_t i = 0;
  for (auto _ : state) {
    auto problem = resolver::parse_candump_line(lines[i], frame);
    benchmark::DoNotOptimize(problem);
    benchmark::DoNotOptimize(frame.data[0]);
    if (++i == lines.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bench_lines().text.size() / lines.size()));
}
BENCHMARK(BM_ParseCandumpLine);

/// Frames with ID 0x100 only (RESOLVER_SAMPLE).
std::vector<CanFrame> resolver_sample_frames() {
  std::vector<CanFrame> out;
  for (const CanFrame& f : bench_frames()) {
    if (f.id == resolver::bench::kIdResolverSample) out.push_back(f);
  }
  return out;
}

void BM_DbcDecodePhysical(benchmark::State& state) {
  const auto db = bench_dbc();
  const resolver::dbc::Message* msg = db->find_message("RESOLVER_SAMPLE");
  const resolver::dbc::Signal* sig = msg != nullptr ? msg->find_signal("rd_angle") : nullptr;
  if (sig == nullptr) {
    state.SkipWithError("RESOLVER_SAMPLE.rd_angle not in the DBC");
    return;
  }
  const auto frames = resolver_sample_frames();
  std::size_t i = 0;
  for (auto _ : state) {
    const CanFrame& f = frames[i];
    double v = resolver::dbc::decode_physical(*sig, std::span<const std::uint8_t>(f.data.data(), f.len));
    benchmark::DoNotOptimize(v);
    if (++i == frames.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DbcDecodePhysical);

void BM_DbcDecodeMessage(benchmark::State& state) {
  const auto db = bench_dbc();
  const resolver::dbc::Message* msg = db->find_message("RESOLVER_SAMPLE");
  if (msg == nullptr) {
    state.SkipWithError("RESOLVER_SAMPLE not in the DBC");
    return;
  }
  const auto frames = resolver_sample_frames();
  std::size_t i = 0;
  for (auto _ : state) {
    const CanFrame& f = frames[i];
    const std::span<const std::uint8_t> data(f.data.data(), f.len);
    double sum = 0.0;
    for (const resolver::dbc::Signal& s : msg->signals) sum += resolver::dbc::decode_physical(s, data);
    benchmark::DoNotOptimize(sum);
    if (++i == frames.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["signals_per_message"] = static_cast<double>(msg->signals.size());
}
BENCHMARK(BM_DbcDecodeMessage);

void BM_FrameDecoder(benchmark::State& state) {
  const resolver::FrameDecoder decoder(bench_dbc(), resolver::SignalMap::bench_default());
  const auto& frames = bench_frames();
  resolver::DecodedPart part;
  resolver::BenchInfo info;
  std::size_t i = 0;
  for (auto _ : state) {
    const resolver::DecodeResult r = decoder.decode(frames[i], part, info);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(part.values[0]);
    if (++i == frames.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FrameDecoder);

void BM_FrameIntake(benchmark::State& state) {
  auto decoder = std::make_shared<const resolver::FrameDecoder>(bench_dbc(), resolver::SignalMap::bench_default());
  std::int64_t samples = 0;
  double sink = 0.0;
  std::int64_t problems = 0;
  resolver::FrameIntake intake(
      decoder, 8,
      resolver::FrameIntake::Callbacks{
          [&](const resolver::BenchSample& s) {
            ++samples;
            sink += s.values[0];
          },
          [](const resolver::BenchInfo&) {},
          [&](std::string_view, const std::string&) { ++problems; }});
  const auto& frames = bench_frames();
  std::size_t i = 0;
  for (auto _ : state) {
    intake.feed(frames[i], i + 1);
    if (++i == frames.size()) i = 0;
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations());
  state.counters["samples_per_frame"] = static_cast<double>(samples) / static_cast<double>(state.iterations());
  if (problems > 1) state.SkipWithError("the synthetic stream produced decode problems");
}
BENCHMARK(BM_FrameIntake);

void BM_HwangUpdate(benchmark::State& state) {
  resolver::HwangIntegralEstimator estimator{resolver::HwangIntegralConfig{}};
  const auto& inputs = bench_inputs();
  std::int64_t k = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    auto rev = estimator.update(static_cast<double>(k) * kDt, inputs[i].theta_rd);
    benchmark::DoNotOptimize(rev);
    ++k;
    if (++i == inputs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["revolutions"] = static_cast<double>(estimator.revolutions());
}
BENCHMARK(BM_HwangUpdate);

void BM_SinCosLsReference(benchmark::State& state) {
  resolver::SinCosLsConfig config;
  config.harmonics = {3};
  resolver::SinCosLeastSquares ls(config);
  const auto& inputs = bench_inputs();
  std::size_t i = 0;
  for (auto _ : state) {
    const resolver::SampleInput& in = inputs[i];
    ls.add(in.sin, in.cos, kPr * in.theta_m_ref);
    if (++i == inputs.size()) i = 0;
  }
  benchmark::DoNotOptimize(ls.state().ref_w);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SinCosLsReference);

void BM_SinCosLsConic(benchmark::State& state) {
  resolver::SinCosLeastSquares ls{resolver::SinCosLsConfig{}};
  const auto& inputs = bench_inputs();
  std::size_t i = 0;
  for (auto _ : state) {
    ls.add(inputs[i].sin, inputs[i].cos);
    if (++i == inputs.size()) i = 0;
  }
  benchmark::DoNotOptimize(ls.state().conic_w);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SinCosLsConic);

void BM_AngleFourierUpdate(benchmark::State& state) {
  resolver::AngleErrorFourier fourier{resolver::AngleFourierConfig{}};
  const auto& inputs = bench_inputs();
  std::size_t i = 0;
  for (auto _ : state) {
    fourier.add(kPr * inputs[i].theta_m_ref, inputs[i].theta_rd);
    if (++i == inputs.size()) i = 0;
  }
  benchmark::DoNotOptimize(fourier);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AngleFourierUpdate);

void BM_CompensateAngle(benchmark::State& state) {
  // The fit of the stream itself (orders 1..4), as the daemon applies it.
  resolver::AngleErrorFourier fourier{resolver::AngleFourierConfig{}};
  const auto& inputs = bench_inputs();
  for (const resolver::SampleInput& in : inputs) fourier.add(kPr * in.theta_m_ref, in.theta_rd);
  const std::optional<resolver::AngleErrorFit> fit = fourier.solve();
  if (!fit) {
    state.SkipWithError("no Fourier fit of the synthetic stream");
    return;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(fit->compensate(inputs[i].theta_rd));
    if (++i == inputs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CompensateAngle);

void BM_CompensateSinCos(benchmark::State& state) {
  resolver::SinCosLsConfig config;
  config.harmonics = {3};
  resolver::SinCosLeastSquares ls(config);
  const auto& inputs = bench_inputs();
  for (const resolver::SampleInput& in : inputs) ls.add(in.sin, in.cos, kPr * in.theta_m_ref);
  const std::optional<resolver::SinCosFit> fit = ls.solve();
  if (!fit) {
    state.SkipWithError("no sin/cos fit of the synthetic stream");
    return;
  }
  const resolver::SinCosCorrection corr = resolver::SinCosCorrection::from_fit(*fit);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(resolver::corrected_angle(corr, inputs[i].sin, inputs[i].cos));
    if (++i == inputs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CompensateSinCos);

void BM_SampleProcessor(benchmark::State& state) {
  resolver::ProcessorConfig config;
  config.p_r = kPr;
  config.p = kP;
  resolver::SampleProcessor processor(config);
  const auto& inputs = bench_inputs();
  std::int64_t k = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    resolver::SampleInput in = inputs[i];
    in.t = static_cast<double>(k) * kDt;
    const resolver::SampleOutput out = processor.process(in);
    benchmark::DoNotOptimize(out);
    ++k;
    if (++i == inputs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SampleProcessor);

void BM_DqTransform(benchmark::State& state) {
  const auto& inputs = bench_inputs();
  std::size_t i = 0;
  for (auto _ : state) {
    const resolver::SampleInput& in = inputs[i];
    const resolver::ClarkeTransform ab(in.i_a, in.i_b, in.i_c);
    const resolver::ParkTransform dq(ab.alpha, ab.beta, kP * in.theta_m_ref);
    benchmark::DoNotOptimize(dq.d);
    benchmark::DoNotOptimize(dq.q);
    if (++i == inputs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DqTransform);

/// Feeds the looped stream through a Pipeline; timestamps keep rising across
/// loops so health_t is published once per second of frame time, as in a log.
void run_pipeline(benchmark::State& state, resolver::OutputSink& sink, bool model_fit = false) {
  NullBuffer null_buffer;
  std::ostream diagnostics(&null_buffer);
  resolver::DaemonConfig config;
  config.dbc_path = RESOLVER_BENCH_DBC;
  // As the replay benchmark's "full pipeline": the live model fit (its own
  // row, BM_PipelineModelFit) waits for a fit per window in replay.
  config.model.enabled = model_fit;
  resolver::Pipeline pipeline(config, sink, diagnostics);
  const auto& frames = bench_frames();
  const std::int64_t loop_us = static_cast<std::int64_t>(kPeriods) * kDtUs;
  std::int64_t offset_us = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    CanFrame f = frames[i];
    f.timestamp_us += offset_us;
    pipeline.feed(f, i + 1, resolver::Pipeline::Clock::now());
    if (++i == frames.size()) {
      i = 0;
      offset_us += loop_us;
    }
  }
  pipeline.finish();
  state.SetItemsProcessed(state.iterations());
  state.counters["samples_per_frame"] =
      static_cast<double>(pipeline.samples()) / static_cast<double>(state.iterations());
}

void BM_PipelineNullSink(benchmark::State& state) {
  NullSink sink;
  run_pipeline(state, sink);
  state.counters["messages_per_frame"] = static_cast<double>(sink.messages) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_PipelineNullSink);

void BM_PipelineModelFit(benchmark::State& state) {
  NullSink sink;
  run_pipeline(state, sink, true);
  state.counters["messages_per_frame"] = static_cast<double>(sink.messages) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_PipelineModelFit);

void BM_PipelineLcmFile(benchmark::State& state) {
  const std::string path = "/tmp/bench_hot_paths_" + std::to_string(::getpid()) + ".lcmlog";
  {
    resolver::LcmChannels channels;
    resolver::LcmOutput sink("file://" + path + "?mode=w", channels);
    run_pipeline(state, sink);
    state.counters["messages_per_frame"] =
        static_cast<double>(sink.published()) / static_cast<double>(state.iterations());
  }
  std::remove(path.c_str());
}
BENCHMARK(BM_PipelineLcmFile);

/// The bench stream as discovery's prepared rows (every signal: R/D, sin/cos, reference, currents).
const resolver::PreparedLog& prepared_bench() {
  static const resolver::PreparedLog log = [] {
    resolver::DiscoveryInput in;
    in.p_r = kPr;
    in.p = kP;
    for (std::size_t k = 0; k < kPeriods; ++k) in.samples.push_back(sample_at(k));
    return resolver::prepare_log(in, {});
  }();
  return log;
}

void BM_DesignPass(benchmark::State& state) {
  const resolver::PreparedLog& log = prepared_bench();
  const resolver::Model model(resolver::ModelSpec::parse(std::vector<std::string>{"amplitude_imbalance"}), log.p_r, log.p);
  resolver::Design d = resolver::design_for(model, log);
  if (state.range(0) == 1) {
    for (const resolver::Effect* e : resolver::effect_registry()) {
      if (e->fittable() && model.spec().find(*e) == nullptr) d.add_candidate({e, resolver::default_params(*e)});
    }
  }
  const resolver::GroupFloors floors = log.floors.floors();
  for (auto _ : state) {
    resolver::PassStatistics stats(d.columns());
    resolver::accumulate(d, log.rows, floors, stats);
    benchmark::DoNotOptimize(stats);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(log.rows.size()));
  state.counters["columns"] = d.columns();
}
BENCHMARK(BM_DesignPass)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// NormalEquations::add per row, by column count: the sums every fit pass, floor and
/// breakdown accumulates (6-10 columns for a model's group, 37 for the floors' basis).
void BM_NormalEquationsAdd(benchmark::State& state) {
  const int columns = static_cast<int>(state.range(0));
  constexpr int kRows = 4096;  // a live window's rows at 10 kHz, 781 r/min
  Eigen::MatrixXd x(columns, kRows);
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < columns; ++c) x(c, r) = std::sin(0.37 * r + 1.3 * c);
  }
  for (auto _ : state) {
    resolver::NormalEquations ne(columns);
    for (int r = 0; r < kRows; ++r) ne.add(x.col(r), x(0, r));
    benchmark::DoNotOptimize(ne.m().data());
  }
  state.SetItemsProcessed(state.iterations() * kRows);
}
BENCHMARK(BM_NormalEquationsAdd)->Arg(4)->Arg(8)->Arg(16)->Arg(26)->Arg(37);

}  // namespace

BENCHMARK_MAIN();
