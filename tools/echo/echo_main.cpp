// resolver-echo: print LCM messages as JSON lines, from an event log or live.
// Wiring only: the work is in resolver_lcm_json (echo_output.h, live_echo.h).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "daemon/app/exit_codes.h"
#include "tools/echo/csv_export.h"
#include "tools/echo/echo_output.h"
#include "tools/echo/lcm_eventlog_reader.h"
#include "tools/echo/lcm_fingerprint.h"
#include "tools/echo/lcm_type_parser.h"
#include "tools/echo/lcm_type_registry.h"
#include "tools/echo/live_echo.h"
#include "tools/echo/json_writer.h"
#include "daemon/service/program_version.h"

namespace {

namespace exit_code = resolver::exit_code;

constexpr const char* kDescription =
    "resolver-echo prints LCM messages as JSON lines, one object per message.\n"
    "It knows the project's types (proto/resolver/*.lcm, compiled in) and decodes\n"
    "any message whose 8-byte fingerprint matches one of them or a type added\n"
    "with --types; there is nothing to regenerate when a type changes.\n"
    "With --csv DIR it writes a log's channels as tables instead, one CSV file per channel.";

constexpr const char* kFooter = R"(Output:
  One JSON object per line, members in declaration order:
    {"channel":"RESOLVER_ANGLE","type":"resolver.angle_t","utime":1700000000123456,
     "sample_index":42,"counter":42,"theta_rd":1.5707963267948966,...}
  "utime" is the message's own utime member, or the log/receive time [us] if its
  type has none. Arrays are JSON arrays, nested structs are objects, NaN and
  +-inf are null (JSON has no NaN), doubles print with enough digits to
  round-trip. A message that cannot be decoded is still printed:
    {"channel":"X","type":null,"utime":null,"size":24,"error":"unknown fingerprint 0x..."}
  Errors about the input go to stderr.

  With --csv DIR: DIR/<channel>.csv per channel (characters other than letters, digits,
  '_', '-', '.' in the name become '_'), one header line and one line per message:
  utime_s (the utime member in seconds, to the microsecond; the log's receive time
  when the type has none), then every numeric member in declaration order, nested
  members joined with '_' and array elements numbered: value_0, value_1 ... (a
  message with fewer elements leaves those fields empty). Booleans are 1/0, NaN and
  infinities NaN/Inf/-Inf; strings are left out. One line per file on stdout.

Examples:
  Everything in a log recorded with lcm-logger:
    resolver-echo --log lcmlog-2024-05-01.00
  Only the corrected angle, first 10 messages, one field with jq:
    resolver-echo --log run.lcmlog --channel RESOLVER_ANGLE --limit 10 | jq .theta_comp
  All estimate_t messages on any channel:
    resolver-echo --log run.lcmlog --type estimate_t
  Live, the next 5 messages on the RESOLVER_ channels (default UDP multicast):
    resolver-echo --lcm udpm://239.255.76.67:7667?ttl=0 --channel 'RESOLVER_.*' --count 5
  Live for 2 seconds, with extra types from another package:
    resolver-echo --lcm udpm:// --timeout 2 --types ~/my_types
  Which types are known, with their fingerprints:
    resolver-echo --list-types
  Every channel of a log as CSV tables (MATLAB readtable, pandas.read_csv):
    resolver-echo --log build/demo/demo.lcmlog --csv build/demo/csv
  Only the dq currents, as build/demo/csv/RESOLVER_DQ.csv:
    resolver-echo --log build/demo/demo.lcmlog --channel RESOLVER_DQ --csv build/demo/csv

Exit status:
  0 done; 1 the input had no usable data (a malformed or truncated log, --timeout expired
  before --count messages arrived, --csv and no message matched); 2 usage error (bad
  option, --type or --channel, a bad .lcm file in --types, a FIFO or pipe as --log); 3 I/O error (--log missing or
  unreadable, LCM cannot start, stdout or a --csv file cannot be written); 4 out of memory; 70 internal error (a bug).)";

void print_line(const std::string& line) {
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
}

/// What the command line asks for.
struct EchoArguments {
  std::string log_path;
  std::string lcm_url;
  std::string channel_regex;
  std::string type_name;
  std::vector<std::string> type_dirs;
  std::optional<std::int64_t> limit;
  std::optional<std::int64_t> count;
  std::optional<double> timeout_s;
  std::string csv_dir;
  bool list_types = false;
};

void add_echo_options(CLI::App& app, EchoArguments& a) {
  auto* log_opt = app.add_option("--log", a.log_path, "read this LCM event log (lcm-logger output or file://)");
  auto* lcm_opt = app.add_option("--lcm", a.lcm_url, "subscribe live to this LCM URL (udpm://..., memq://...)");
  app.add_flag("--list-types", a.list_types, "print the known types and their fingerprints, then exit");
  log_opt->excludes(lcm_opt);
  lcm_opt->excludes(log_opt);
  app.add_option("--channel", a.channel_regex, "only channels fully matching this regex (ECMAScript), e.g. 'RESOLVER_.*'");
  app.add_option("--type", a.type_name, "only messages of this type: resolver.angle_t or angle_t");
  app.add_option("--types", a.type_dirs, "also load the *.lcm files in this directory (repeatable)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--limit", a.limit, "--log: stop after printing N messages")
                        ->check(CLI::PositiveNumber)->needs(log_opt);
  app.add_option("--count", a.count, "--lcm: exit after printing N messages")
                        ->check(CLI::PositiveNumber)->needs(lcm_opt);
  app.add_option("--timeout", a.timeout_s, "--lcm: exit after SEC seconds (default: never)")
                          ->check(CLI::PositiveNumber)->needs(lcm_opt);
  app.add_option("--csv", a.csv_dir, "--log: write each channel as DIR/<channel>.csv (numeric members, a utime_s "
                                     "column) instead of JSON lines; DIR is created when missing")
      ->needs(log_opt);
}

/// No input throws InputError (usage: exit 2); a --log that cannot be read IoError (exit 3).
void check_input(const EchoArguments& a) {
  if (!a.list_types && a.log_path.empty() && a.lcm_url.empty()) {
    throw resolver::InputError(resolver::Fault::kUsage, "give --log FILE or --lcm URL (or --list-types); see --help");
  }
  if (!a.log_path.empty()) exit_code::require_readable("--log", a.log_path);
}

/// The --types directories into the registry: a bad .lcm file throws LcmParseError (an
/// InputError, usage: exit 2); what the registry could not resolve are warnings.
void add_type_dirs(resolver::LcmTypeRegistry& registry, const std::vector<std::string>& type_dirs) {
  for (const auto& dir : type_dirs) registry.add_directory(dir);
  for (const auto& problem : registry.problems()) std::cerr << "resolver-echo: warning: " << problem << '\n';
}

/// --list-types: one line per type, its fingerprint first.
void print_types(const resolver::LcmTypeRegistry& registry) {
  for (const auto* t : registry.types()) {
    const auto fp = registry.fingerprint_of(t->full_name());
    std::cout << (fp ? resolver::hex64(*fp) : std::string("(unresolved)      ")) << "  " << t->full_name()
              << "  (" << t->source << ")\n";
  }
}

/// --type names a known type, by its full or its short name.
bool type_known(const resolver::LcmTypeRegistry& registry, const std::string& type_name) {
  if (registry.find_by_name(type_name) != nullptr) return true;
  bool short_name_known = false;
  for (const auto* t : registry.types()) short_name_known = short_name_known || t->name == type_name;
  return short_name_known;
}

/// --csv DIR: the log's channels as tables, one line per file on stdout.
int write_csv_tables(const EchoArguments& a, const resolver::LcmJsonDecoder& decoder,
                     const resolver::EchoFilter& filter) {
  // A malformed log throws EventLogError (exit 1), a file that cannot be written IoError (exit 3).
  const resolver::CsvExportResult written = resolver::export_log_csv(a.log_path, decoder, filter, a.limit, a.csv_dir);
  for (const auto& f : written.files) {
    std::cout << fmt::format("wrote {}: {} rows x {} columns ({} on channel {})\n", f.path, f.rows, f.columns,
                             fmt::join(f.types, ", "), f.channel);
  }
  if (written.undecoded > 0) {
    std::cerr << fmt::format("resolver-echo: --csv: {} message(s) could not be decoded and are not in a table "
                             "(the first: {}); resolver-echo --log shows them\n",
                             written.undecoded, written.first_undecoded_error);
  }
  if (written.files.empty()) {
    std::cerr << "resolver-echo: --csv: no message " << (written.undecoded > 0 ? "could be decoded" : "matched")
              << "; nothing written\n";
    return exit_code::kNoUsableData;
  }
  return std::fflush(stdout) == 0 ? exit_code::kDone : exit_code::kIo;
}

/// --lcm URL: the messages as they arrive, until --count or --timeout.
int echo_live(const EchoArguments& a, const resolver::LcmJsonDecoder& decoder, const resolver::EchoFilter& filter) {
  lcm::LCM lcm(a.lcm_url);
  std::optional<std::chrono::milliseconds> timeout;
  if (a.timeout_s) timeout = std::chrono::milliseconds(static_cast<std::int64_t>(*a.timeout_s * 1000.0));
  resolver::LiveEcho live(lcm, decoder, filter, [](const std::string& line) {
    print_line(line);
    std::fflush(stdout);  // live output is watched or piped: do not sit in a buffer
  });
  // LCM or the output failing throws IoError "--lcm URL: ...": exit 3.
  const auto result = live.run(a.count, timeout, resolver::Where::at_option("--lcm " + a.lcm_url));
  if (a.count && result.emitted < *a.count) {
    std::cerr << fmt::format("resolver-echo: --timeout {} s expired after {} of --count {} messages\n", *a.timeout_s,
                             result.emitted, *a.count);
    return exit_code::kNoUsableData;
  }
  return exit_code::kDone;
}

/// The types, then --list-types, or the filter and the log (as JSON lines or CSV) or the live bus.
int echo(const EchoArguments& a) {
  resolver::LcmTypeRegistry registry = resolver::LcmTypeRegistry::with_embedded_types();
  add_type_dirs(registry, a.type_dirs);
  if (a.list_types) {
    print_types(registry);
    return 0;
  }
  if (!a.type_name.empty() && !type_known(registry, a.type_name)) {
    throw resolver::InputError(resolver::Fault::kUsage, "no such type; see --list-types or add it with --types",
                               resolver::Where::at_option("--type " + a.type_name));
  }
  // A bad --channel regex throws std::invalid_argument: exit 2.
  const resolver::EchoFilter filter = resolver::make_echo_filter(a.channel_regex, a.type_name);
  const resolver::LcmJsonDecoder decoder(registry);
  if (!a.log_path.empty() && !a.csv_dir.empty()) return write_csv_tables(a, decoder, filter);
  if (!a.log_path.empty()) {
    resolver::echo_log_file(a.log_path, decoder, filter, a.limit, print_line);
    return std::fflush(stdout) == 0 ? exit_code::kDone : exit_code::kIo;
  }
  return echo_live(a, decoder, filter);
}

int run(int argc, char** argv) {
  CLI::App app{kDescription, "resolver-echo"};
  app.footer(kFooter);
  app.set_version_flag("--version", resolver::version_line("resolver-echo"));
  app.get_formatter()->column_width(28);
  EchoArguments a;
  add_echo_options(app, a);
  if (auto code = exit_code::parse_command_line(app, argc, argv)) return *code;
  check_input(a);
  try {
    return echo(a);
  } catch (...) {
    std::fflush(stdout);  // the messages echoed before the failure come first
    throw;
  }
}

}  // namespace

// What run() throws gets its exit code from the one rule (program_errors.h): a
// malformed or truncated log (EventLogError) 1, a file that cannot be read 3, ...
int main(int argc, char** argv) {
  return resolver::run_program("resolver-echo", [&] { return run(argc, argv); });
}
