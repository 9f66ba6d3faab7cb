#include "tools/model/log_samples.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/app/log_input.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/signal_health_log.h"
#include "daemon/decode/sample_stream.h"
#include "daemon/core/errors.h"

namespace resolver {

namespace {

/// Decode problems by reason.
using ProblemCounts = std::map<std::string, std::int64_t, std::less<>>;
/// Bad lines by reason: how many, and the first (file:line:column: message).
using BadLineReasons = std::map<std::string, std::pair<std::int64_t, std::string>, std::less<>>;

/// How the records ran out, and the lines that were not read.
struct RecordsRead {
  bool at_end = false;  // the end of the file, not of --to
  BadLineReasons bad_line_reasons;
};

/// Every record into the stream until the end of the file or of the slice; counts
/// frames and bad lines into `out`, and calls progress every 4096 records.
RecordsRead feed_records(LogInput& reader, SampleStream& stream, const std::string& path,
                         const std::function<void(const LogReadProgress&)>& progress, LogSamples& out) {
  RecordsRead read;
  LogRecord record;
  std::int64_t since_progress = 0;
  while (!stream.past_slice_end()) {
    const auto st = reader.next(record);
    if (st == LogInput::Status::kEnd) {
      read.at_end = true;
      break;
    }
    if (st == LogInput::Status::kBadLine) {
      ++out.bad_lines;
      // By reason, with the first line of each: resolverd prints them; here they are notes.
      const TextProblem& p = reader.problem();
      auto [it, first] = read.bad_line_reasons.try_emplace(p.reason, 0, std::string());
      if (first) it->second.second = fmt::format("{}:{}:{}: {}", path, reader.line_number(), p.column, p.message);
      ++it->second.first;
      continue;
    }
    ++out.frames;
    if (record.is_row) {
      stream.feed_row(record.row, reader.line_number());
    } else {
      stream.feed(record.frame, reader.line_number());
    }
    if (progress && ++since_progress >= 4096) {  // a std::function call per 4096 records: not measurable
      since_progress = 0;
      progress(LogReadProgress{reader.bytes_read(), reader.total_bytes(),
                               static_cast<std::int64_t>(out.input.samples.size()) + out.chunked_samples, false});
    }
  }
  return read;
}

/// Cuts the samples into chunks of `chunk_s` of sample time and hands each on one
/// chunk late, so that a short last piece can join the chunk before it.
class SampleChunker {
 public:
  SampleChunker(double chunk_s, std::function<void(DiscoveryInput&&)> emit) : chunk_s_(chunk_s), emit_(std::move(emit)) {}

  void add(const Sample& s, int p_r, int p) {
    // Time as the clock runs: a step back (a re-anchored clock) adds nothing.
    if (!current_.samples.empty()) span_ += std::max(0.0, s.t - current_.samples.back().t);
    if (span_ >= chunk_s_) {
      if (!pending_.samples.empty()) emit_(std::move(pending_));
      pending_ = std::move(current_);
      current_ = DiscoveryInput{};
      span_ = 0.0;
    }
    current_.p_r = p_r;
    current_.p = p;
    current_.samples.push_back(s);
  }

  void finish() {
    if (!pending_.samples.empty() && !current_.samples.empty() && span_ < 0.5 * chunk_s_) {
      pending_.samples.insert(pending_.samples.end(), current_.samples.begin(), current_.samples.end());
      current_ = DiscoveryInput{};
    }
    if (!pending_.samples.empty()) emit_(std::move(pending_));
    if (!current_.samples.empty()) emit_(std::move(current_));
  }

 private:
  double chunk_s_;
  std::function<void(DiscoveryInput&&)> emit_;
  DiscoveryInput pending_, current_;
  double span_ = 0.0;
};

/// A regular file read to its end has given exactly the bytes it had when opened.
/// Fewer: it was truncated or replaced while read, and the samples may mix two logs
/// (thrown). More: a log still being written (candump -l running); the samples are
/// those read (a note).
void check_size_while_read(const LogInput& reader, bool at_end, const std::string& path, LogSamples& out) {
  const std::uint64_t at_open = reader.total_bytes();  // 0: a FIFO, pipe or device
  if (at_end && at_open > 0 && reader.bytes_read() < at_open) {
    throw IoError(fmt::format("{}: the file shrank while it was read: {} bytes when opened, its end came after {} "
                              "(truncated, or replaced by another file?); read a copy that nothing writes to",
                              path, at_open, reader.bytes_read()));
  }
  if (at_end && at_open > 0 && reader.bytes_read() > at_open) {
    out.grew_while_read = fmt::format("{} grew while it was read ({} bytes when opened, {} read to the end): a log "
                                      "still being written; these are the samples of the bytes read, and a last "
                                      "line cut short counts as a bad line",
                                      path, at_open, reader.bytes_read());
    out.notes.push_back(out.grew_while_read);
  }
}

/// No sample at all: all of them outside --from/--to, or none decoded with the layout in use.
[[noreturn]] void throw_no_samples(const std::string& path, LogFormat format, const DaemonConfig& config,
                                   const FrameDecoder& decoder, const SampleSlice& slice, const LogSamples& out,
                                   double last_t) {
  if (slice.limited() && out.outside_slice > 0) {
    const std::string to = std::isfinite(slice.to_s) ? fmt::format(" to --to {} s", slice.to_s) : "";
    throw InputError(Fault::kData,
                     fmt::format("no samples from --from {} s{}: the log's {} samples span 0 .. {:.6g} s",
                                 slice.from_s, to, out.outside_slice, last_t),
                     Where::at_file(path));
  }
  const std::string layout = format == LogFormat::kCsv ? "the [input.csv] column map of " + config.source
                                                       : describe_layout(config, decoder);
  throw InputError(Fault::kData,
                   fmt::format("no samples: {} {} read as {}, {} bad lines, none decoded with {}", out.frames,
                               format == LogFormat::kCsv ? "rows" : "frames", log_format_name(format), out.bad_lines,
                               layout),
                   Where::at_file(path));
}

/// The notes of a read: where p_r and p came from, clock re-anchors, lines not read,
/// gaps and the slice.
void add_read_notes(LogSamples& out, const DaemonConfig& config, const SampleSlice& slice,
                    const ProblemCounts& problem_counts, const BadLineReasons& bad_line_reasons) {
  if (!out.bench_info) {
    out.notes.push_back("p_r = " + std::to_string(out.input.p_r) + ", p = " + std::to_string(out.input.p) + " from " +
                        (config.source.empty() ? std::string("the defaults") : config.source) +
                        (config.bench.use_bench_info ? " (no BENCH_INFO frame in the log)" : " (use_bench_info = false)"));
  }
  for (const char* odd : {"timestamp_step_back", "timestamp_jump", "sample_clock_reanchored"}) {
    const auto it = problem_counts.find(odd);
    if (it != problem_counts.end()) {
      out.notes.push_back(fmt::format("{}: {} (the sample clock re-anchored; every sample after it used)", odd, it->second));
    }
  }
  for (const auto& [reason, seen] : bad_line_reasons) {
    out.notes.push_back(fmt::format("{}: {} line(s) not read, the first: {}", reason, seen.first, seen.second));
  }
  if (const auto it = problem_counts.find("sample_gap"); it != problem_counts.end()) {
    out.notes.push_back(fmt::format("sample_gap: {} (samples missing from the recording, found from time)", it->second));
  }
  if (slice.limited()) {
    out.notes.push_back(fmt::format("slice {} s .. {} s: {} samples used, {} outside", slice.from_s, slice.to_s,
                                    out.input.samples.size() + static_cast<std::size_t>(out.chunked_samples), out.outside_slice));
  }
}

}  // namespace

LogSamples read_log_samples(const std::string& path, const std::function<void(const LogReadProgress&)>& progress,
                            const DaemonConfig& config, const LogReadOptions& options) {
  LogSamples out;
  out.input.p_r = config.bench.p_r;
  out.input.p = config.bench.p;
  const LogFormat format = resolve_log_format(path, options.format, config);
  const std::unique_ptr<LogInput> reader = open_log_input(path, format, config);  // throws "cannot open <path>: ..."
  const auto decoder = make_frame_decoder(config);
  ProblemCounts problem_counts;
  SignalHealthMonitor health(health_config_for(config, *decoder), config.bench.p_r, config.bench.sample_rate_hz);
  if (format == LogFormat::kCsv && !config.health_full_scale_set) {
    health.set_full_scale(csv_sincos_full_scale(config.csv.map), 0.0);  // as resolverd's Pipeline::feed_row
  }
  std::optional<SampleChunker> chunker;
  if (options.chunk_s > 0.0 && options.on_chunk) chunker.emplace(options.chunk_s, options.on_chunk);
  SampleStream stream(decoder, sample_stream_config(config, options.slice),
                      SampleStream::Callbacks{
                          [&](const Sample& s, std::uint8_t) {
                            if (chunker) {
                              chunker->add(s, out.input.p_r, out.input.p);
                              ++out.chunked_samples;
                            } else {
                              out.input.samples.push_back(s);
                            }
                            health.add(s);
                          },
                          [&](const BenchInfo& i) {
                            if (config.bench.use_bench_info && i.p_r >= 1 && i.p >= 1) {
                              out.input.p_r = i.p_r;
                              out.input.p = i.p;
                              out.bench_info = true;
                              health.set_pole_pairs(i.p_r);
                            }
                            if (i.sample_rate_hz > 0.0) health.set_sample_rate(i.sample_rate_hz);
                          },
                          [&](std::string_view reason, const std::string&) {
                            ++out.problems;
                            ++problem_counts[std::string(reason)];
                          }});
  const RecordsRead read = feed_records(*reader, stream, path, progress, out);
  check_size_while_read(*reader, read.at_end, path, out);
  stream.flush();
  if (chunker) chunker->finish();
  health.finish();
  out.faults = health.faults();
  out.health_samples = health.samples();
  out.outside_slice = stream.samples_outside_slice();
  if (std::string note = stream.intake().interface_note(); !note.empty()) out.notes.push_back(std::move(note));
  if (progress) {
    progress(LogReadProgress{reader->bytes_read(), reader->total_bytes(),
                             static_cast<std::int64_t>(out.input.samples.size()) + out.chunked_samples, true});
  }
  if (out.input.samples.empty() && out.chunked_samples == 0) {
    throw_no_samples(path, format, config, *decoder, options.slice, out, stream.clock().last_t());
  }
  add_read_notes(out, config, options.slice, problem_counts, read.bad_line_reasons);
  return out;
}

FaultCounts fault_counts(const LogSamples& log) {
  FaultCounts c{};
  for (std::size_t i = 0; i < kSignalFaultCount; ++i) c[i] = log.faults[i].samples;
  return c;
}

std::vector<std::string> input_notes(const LogSamples& samples) {
  std::vector<std::string> notes = samples.notes;
  if (samples.bad_lines > 0) notes.push_back(std::to_string(samples.bad_lines) + " malformed log lines skipped");
  if (samples.problems > 0) notes.push_back(std::to_string(samples.problems) + " input problems counted (by reason above: a gap is counted, not skipped)");
  return notes;
}

}  // namespace resolver
