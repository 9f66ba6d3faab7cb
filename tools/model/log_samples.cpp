#include "tools/model/log_samples.h"

#include <stdexcept>

#include "daemon/app/pipeline.h"
#include "daemon/decode/frame_intake.h"
#include "daemon/decode/signal_map.h"
#include "drivers/candump/candump_reader.h"

namespace resolver {

LogSamples read_log_samples(const std::string& path, const std::function<void(double)>& progress,
                            const DaemonConfig& config) {
  LogSamples out;
  out.input.p_r = config.bench.p_r;
  out.input.p = config.bench.p;
  CandumpReader reader(path);  // throws "cannot open <path>: <strerror>"
  std::int64_t first_us = -1;
  FrameIntake intake(make_frame_decoder(config), config.max_counter_delta,
                     FrameIntake::Callbacks{
                         [&](const BenchSample& s) {
                           if (first_us < 0) first_us = s.timestamp_us;
                           Sample d;
                           d.t = static_cast<double>(s.timestamp_us - first_us) * 1e-6;
                           d.has_rd = s.has(Role::kRdAngle);
                           d.theta_rd = s.get(Role::kRdAngle);
                           d.has_sincos = s.has(Role::kSin) && s.has(Role::kCos);
                           d.sin = s.get(Role::kSin);
                           d.cos = s.get(Role::kCos);
                           d.has_ref = s.has(Role::kRefAngle);
                           d.theta_m_ref = s.get(Role::kRefAngle);
                           d.has_currents = s.has(Role::kIA) && s.has(Role::kIB) && s.has(Role::kIC);
                           d.i_a = s.get(Role::kIA);
                           d.i_b = s.get(Role::kIB);
                           d.i_c = s.get(Role::kIC);
                           out.input.samples.push_back(d);
                         },
                         [&](const BenchInfo& i) {
                           if (config.bench.use_bench_info && i.p_r >= 1 && i.p >= 1) {
                             out.input.p_r = i.p_r;
                             out.input.p = i.p;
                             out.bench_info = true;
                           }
                         },
                         [&](std::string_view, const std::string&) { ++out.problems; }});
  CanFrame frame;
  std::int64_t since_progress = 0;
  for (;;) {
    const auto st = reader.next(frame);
    if (st == CandumpReader::Status::kEnd) break;
    if (st == CandumpReader::Status::kBadLine) {
      ++out.bad_lines;
      continue;
    }
    ++out.frames;
    intake.feed(frame, reader.line_number());
    if (progress && ++since_progress >= 20000 && reader.total_bytes() > 0) {
      since_progress = 0;
      progress(static_cast<double>(reader.bytes_read()) / static_cast<double>(reader.total_bytes()));
    }
  }
  intake.flush();
  if (progress) progress(1.0);
  if (out.input.samples.empty()) {
    throw std::runtime_error(path + ": no samples: " + std::to_string(out.frames) + " frames, " +
                             std::to_string(out.bad_lines) +
                             " bad lines, none decoded as the default bench layout (RESOLVER_SAMPLE 0x100 ...)");
  }
  if (!out.bench_info) {
    out.notes.push_back("p_r = " + std::to_string(out.input.p_r) + ", p = " + std::to_string(out.input.p) + " from " +
                        (config.source.empty() ? std::string("the defaults") : config.source) +
                        (config.bench.use_bench_info ? " (no BENCH_INFO frame in the log)" : " (use_bench_info = false)"));
  }
  return out;
}

}  // namespace resolver
