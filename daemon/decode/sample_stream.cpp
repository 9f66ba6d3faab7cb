#include "daemon/decode/sample_stream.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <fmt/format.h>

namespace resolver {

Sample to_sample(const BenchSample& s, const ClockReading& clock) {
  Sample out;
  out.t = clock.t;
  out.index = clock.index;
  out.utime = s.timestamp_us;
  out.has_rd = s.has(Role::kRdAngle);
  out.theta_rd = s.get(Role::kRdAngle);
  out.has_sincos = s.has(Role::kSin) && s.has(Role::kCos);
  out.sin = s.get(Role::kSin);
  out.cos = s.get(Role::kCos);
  out.has_ref = s.has(Role::kRefAngle);
  out.theta_m_ref = s.get(Role::kRefAngle);
  out.has_currents = s.has(Role::kIA) && s.has(Role::kIB) && s.has(Role::kIC);
  out.i_a = s.get(Role::kIA);
  out.i_b = s.get(Role::kIB);
  out.i_c = s.get(Role::kIC);
  return out;
}

SampleStream::SampleStream(std::shared_ptr<const FrameDecoder> decoder, const SampleStreamConfig& config,
                           Callbacks callbacks)
    : config_(config),
      callbacks_(std::move(callbacks)),
      intake_(std::move(decoder), config.clock.max_counter_delta,
              FrameIntake::Callbacks{[this](const BenchSample& s) { on_joined(s); },
                                     [this](const BenchInfo& info) {
                                       if (config_.use_bench_info) clock_.set_sample_rate(info.sample_rate_hz);
                                       if (callbacks_.on_bench_info) callbacks_.on_bench_info(info);
                                     },
                                     [this](std::string_view reason, const std::string& message) {
                                       if (callbacks_.on_problem) callbacks_.on_problem(reason, message);
                                     }}),
      clock_(config.clock) {}

void SampleStream::restart_sequence() {
  release_rows();
  row_passed_ = false;  // the next pass starts over in time
  intake_.restart_sequence();
  clock_.restart();
}

void SampleStream::reconfigure(std::shared_ptr<const FrameDecoder> decoder, const SampleStreamConfig& config) {
  const SampleSlice slice = config_.slice;
  release_rows();
  if (decoder || config.clock.max_counter_delta != config_.clock.max_counter_delta) {
    intake_.change_decoder(decoder ? std::move(decoder) : intake_.decoder_ptr(), config.clock.max_counter_delta);
  }
  config_ = config;
  config_.slice = slice;
  clock_.reconfigure(config.clock);
}

void SampleStream::feed_row(const RowSample& row, std::uint64_t line) {
  if (!row.has_time) {
    pass_row(row, line);  // the row number is the sample number: nothing to reorder
    return;
  }
  if (row_passed_ && row.time_us < last_row_us_) {
    // Before a row already passed on: a step back (the clock counts it), not a swap.
    release_rows();
    pass_row(row, line);
    return;
  }
  auto at = waiting_rows_.end();
  while (at != waiting_rows_.begin() && std::prev(at)->row.time_us > row.time_us) --at;
  if (at != waiting_rows_.end()) {
    intake_.count_problem(
        "rows_reordered",
        fmt::format("line {}: row at {} comes before line {}'s {} in time: rows out of order, used in time order "
                    "(not lost)",
                    line, describe_frame_time(row.time_us), at->line, describe_frame_time(at->row.time_us)));
  }
  waiting_rows_.insert(at, WaitingRow{row, line});
  const auto window = static_cast<std::size_t>(std::max(1, config_.clock.max_counter_delta));
  if (waiting_rows_.size() > window) {
    const WaitingRow first = waiting_rows_.front();
    waiting_rows_.erase(waiting_rows_.begin());
    pass_row(first.row, first.line);
  }
}

void SampleStream::release_rows() {
  std::vector<WaitingRow> rows = std::move(waiting_rows_);
  waiting_rows_.clear();
  for (const WaitingRow& w : rows) pass_row(w.row, w.line);
}

void SampleStream::pass_row(const RowSample& row, std::uint64_t line) {
  line_ = line;
  if (row.has_time) {
    row_passed_ = true;
    last_row_us_ = row.time_us;
  }
  BenchSample s;
  s.roles = row.roles;
  s.values = row.values;
  s.index = row.sequence;
  // Without a time column the row number is the sample number and the row
  // rate its clock, exactly as a counter and a sample rate are for frames.
  s.has_counter = !row.has_time;
  if (row.has_time) {
    s.timestamp_us = row.time_us;
  } else {
    clock_.set_sample_rate(config_.row_rate_hz);
    s.timestamp_us = config_.row_rate_hz > 0.0
                         ? std::llround(static_cast<double>(row.sequence) * 1e6 / config_.row_rate_hz)
                         : row.sequence;
  }
  s.counter = static_cast<std::uint8_t>(row.sequence & 0xFF);
  intake_.feed_sample(s);
}

void SampleStream::on_joined(const BenchSample& joined) {
  const ClockReading r =
      clock_.read(joined.timestamp_us, joined.has_counter ? std::optional<std::int64_t>(joined.index) : std::nullopt);
  if (r.event != ClockEvent::kNone) report_clock_event(joined, r);
  if (!config_.slice.contains(r.t)) {
    ++outside_slice_;
    if (r.t > config_.slice.to_s) past_slice_end_ = true;
    return;
  }
  if (callbacks_.on_sample) callbacks_.on_sample(to_sample(joined, r), joined.counter);
}

void SampleStream::report_clock_event(const BenchSample& joined, const ClockReading& r) {
  const std::string where = fmt::format("{}sample {} at {}", line_ > 0 ? fmt::format("line {}: ", line_) : std::string(),
                                        r.index, describe_frame_time(joined.timestamp_us));
  const bool counter_time = clock_.uses_counter_time();
  switch (r.event) {
    case ClockEvent::kNone: break;
    case ClockEvent::kStepBack:
      intake_.count_problem(
          "timestamp_step_back",
          fmt::format("{}: the timestamp goes back {:.6f} s from the previous sample's; {}", where, -r.step_s,
                      counter_time && r.index_step <= config_.clock.max_counter_delta
                          ? "time continues from the counter"
                          : "time continues one sample period after the previous sample (logs appended?)"));
      break;
    case ClockEvent::kJump:
      intake_.count_problem(
          "timestamp_jump",
          fmt::format("{}: the timestamp jumps forward {:.6f} s{}; read as a clock jump, {}", where, r.step_s,
                      joined.has_counter ? fmt::format(" while the counter advanced by {}", r.index_step)
                                         : std::string(" (more than an hour, with no counter to count it)"),
                      counter_time ? "time continues from the counter"
                                   : "time continues one sample period after the previous sample"));
      break;
    case ClockEvent::kOutage:
      intake_.count_problem(
          "sample_clock_reanchored",
          fmt::format("{}: arrived {:.6f} s after the previous sample, more than its counter step ({}) explains and "
                      "more than a u8 counter can count: time base re-anchored on the frame clock",
                      where, r.step_s, r.index_step));
      break;
    case ClockEvent::kGap:
      intake_.count_problem("sample_gap",
                            fmt::format("{}: {:.6f} s after the previous sample, {:.1f} sample periods of {:.6f} s: "
                                        "{} sample(s) lost",
                                        where, r.step_s, r.step_s / clock_.period_s(), clock_.period_s(),
                                        r.samples_lost));
      intake_.count_problem_silently("samples_lost", r.samples_lost);
      break;
  }
}

}  // namespace resolver
