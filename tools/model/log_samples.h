// A log as model-discovery samples, through the same input path as resolverd:
// LogInput (candump, Vector ASC or CSV; daemon/app/log_input.h) -> SampleStream
// (the config's DBC and signal map or CSV column map, units, joining, the
// sample clock and the slice; daemon/decode/sample_stream.h) -> Sample. So
// resolver-model fits exactly the samples, at exactly the times, that
// resolverd's processor gets. p_r, p come from BENCH_INFO when the log has it
// (unless the config says use_bench_info = false), else the config's [bench]
// values, and a note says so.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/health/signal_health.h"
#include "daemon/decode/sample_slice.h"

namespace resolver {

struct LogSamples;

/// What the reader said and counted, in the report's words: its notes, the malformed
/// lines skipped, the input problems counted (every program prints these, and a
/// statistics file keeps them).
[[nodiscard]] std::vector<std::string> input_notes(const LogSamples& samples);

struct LogSamples {
  DiscoveryInput input;
  std::int64_t frames = 0;         ///< frames (or CSV rows) read
  std::int64_t bad_lines = 0;
  std::int64_t problems = 0;       ///< decode problems (CRC, counters, odd time, ...)
  std::int64_t outside_slice = 0;  ///< samples before --from or after --to
  bool bench_info = false;
  std::string grew_while_read;     ///< a log still being written: the note (also in notes) that says so
  std::vector<std::string> notes;  ///< what the log lacks, what was odd
  /// Signal health over every sample read, judged as resolverd judges it ([health],
  /// the DBC's or the CSV column's full scale): what each fault held for.
  std::array<SignalFaultState, kSignalFaultCount> faults{};
  std::int64_t health_samples = 0;
  std::int64_t chunked_samples = 0;  ///< samples handed to LogReadOptions::on_chunk
};

/// Samples each fault held for (lasting_faults(), signal_health.h, words them).
[[nodiscard]] FaultCounts fault_counts(const LogSamples& log);

/// How far read_log_samples() is: called every few thousand records and once at the end.
struct LogReadProgress {
  std::uint64_t bytes_read = 0;
  std::uint64_t total_bytes = 0;  ///< 0: not known (a FIFO or pipe)
  std::int64_t samples = 0;
  bool done = false;  ///< the last call: the end of the log (or of --to)
};

struct LogReadOptions {
  std::optional<LogFormat> format;  ///< --format; nullopt: [input] format, else the extension
  SampleSlice slice;                ///< --from/--to [s]
  /// [s] > 0: the samples are handed to on_chunk in chunks of this much sample time
  /// instead of being kept (LogSamples::input stays empty): a log of any length in the
  /// memory of two chunks. A last piece shorter than half a chunk joins the chunk
  /// before it; none is dropped.
  double chunk_s = 0.0;
  std::function<void(DiscoveryInput&& chunk)> on_chunk;
};

/// Reads `path`. progress(how far) is called every 4096 records and at the end
/// (may be empty). Throws std::system_error "cannot open <path>: ..." when the
/// file cannot be read or shrank while it was read (IoError), InputError
/// (Fault::kData) "<path>: no samples ..." (naming the layout in use) when nothing
/// decodes, and ConfigError when the config's DBC, signal map or CSV column map is
/// bad. A file that grew while it was read is read to the end met (grew_while_read says so).
[[nodiscard]] LogSamples read_log_samples(const std::string& path,
                                          const std::function<void(const LogReadProgress&)>& progress,
                                          const DaemonConfig& config = DaemonConfig{},
                                          const LogReadOptions& options = {});

}  // namespace resolver
