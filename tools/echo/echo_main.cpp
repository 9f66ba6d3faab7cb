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

#include "tools/echo/echo_output.h"
#include "tools/echo/lcm_eventlog_reader.h"
#include "tools/echo/lcm_fingerprint.h"
#include "tools/echo/lcm_type_parser.h"
#include "tools/echo/lcm_type_registry.h"
#include "tools/echo/live_echo.h"
#include "tools/echo/json_writer.h"
#include "daemon/service/program_version.h"

namespace {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitTimeout = 3;

constexpr const char* kDescription =
    "resolver-echo prints LCM messages as JSON lines, one object per message.\n"
    "It knows the project's types (proto/resolver/*.lcm, compiled in) and decodes\n"
    "any message whose 8-byte fingerprint matches one of them or a type added\n"
    "with --types; there is nothing to regenerate when a type changes.";

constexpr const char* kFooter = R"(OUTPUT
  One JSON object per line, members in declaration order:
    {"channel":"RESOLVER_ANGLE","type":"resolver.angle_t","utime":1700000000123456,
     "sample_index":42,"counter":42,"theta_rd":1.5707963267948966,...}
  "utime" is the message's own utime member, or the log/receive time [us] if its
  type has none. Arrays are JSON arrays, nested structs are objects, NaN and
  +-inf are null (JSON has no NaN), doubles print with enough digits to
  round-trip. A message that cannot be decoded is still printed:
    {"channel":"X","type":null,"utime":null,"size":24,"error":"unknown fingerprint 0x..."}
  Errors about the input go to stderr.

EXAMPLES
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

EXIT STATUS
  0 done; 1 bad input (unreadable or malformed log, bad .lcm file, LCM failure);
  2 bad command line; 3 --timeout expired before --count messages arrived.)";

void print_line(const std::string& line) {
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{kDescription, "resolver-echo"};
  app.footer(kFooter);
  app.set_version_flag("--version", resolver::version_line("resolver-echo"));
  app.get_formatter()->column_width(28);

  std::string log_path;
  std::string lcm_url;
  std::string channel_regex;
  std::string type_name;
  std::vector<std::string> type_dirs;
  std::optional<std::int64_t> limit;
  std::optional<std::int64_t> count;
  std::optional<double> timeout_s;
  bool list_types = false;

  auto* log_opt = app.add_option("--log", log_path, "read this LCM event log (lcm-logger output or file://)")
                      ->check(CLI::ExistingFile);
  auto* lcm_opt = app.add_option("--lcm", lcm_url, "subscribe live to this LCM URL (udpm://..., memq://...)");
  app.add_flag("--list-types", list_types, "print the known types and their fingerprints, then exit");
  log_opt->excludes(lcm_opt);
  lcm_opt->excludes(log_opt);
  app.add_option("--channel", channel_regex, "only channels fully matching this regex (ECMAScript), e.g. 'RESOLVER_.*'");
  app.add_option("--type", type_name, "only messages of this type: resolver.angle_t or angle_t");
  app.add_option("--types", type_dirs, "also load the *.lcm files in this directory (repeatable)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--limit", limit, "--log: stop after printing N messages")
                        ->check(CLI::PositiveNumber)->needs(log_opt);
  app.add_option("--count", count, "--lcm: exit after printing N messages")
                        ->check(CLI::PositiveNumber)->needs(lcm_opt);
  app.add_option("--timeout", timeout_s, "--lcm: exit after SEC seconds (default: never)")
                          ->check(CLI::PositiveNumber)->needs(lcm_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError too; app.exit() prints it and returns 0 for it.
    return app.exit(e) == 0 ? 0 : kExitUsage;
  }

  if (!list_types && log_path.empty() && lcm_url.empty()) {
    std::cerr << "resolver-echo: give --log FILE or --lcm URL (or --list-types); see --help\n";
    return kExitUsage;
  }

  try {
    resolver::LcmTypeRegistry registry = resolver::LcmTypeRegistry::with_embedded_types();
    for (const auto& dir : type_dirs) registry.add_directory(dir);
    for (const auto& problem : registry.problems()) std::cerr << "resolver-echo: warning: " << problem << '\n';

    if (list_types) {
      for (const auto* t : registry.types()) {
        const auto fp = registry.fingerprint_of(t->full_name());
        std::cout << (fp ? resolver::hex64(*fp) : std::string("(unresolved)      ")) << "  " << t->full_name()
                  << "  (" << t->source << ")\n";
      }
      return 0;
    }
    if (!type_name.empty() && registry.find_by_name(type_name) == nullptr) {
      bool short_name_known = false;
      for (const auto* t : registry.types()) short_name_known = short_name_known || t->name == type_name;
      if (!short_name_known) {
        std::cerr << fmt::format("resolver-echo: --type {}: no such type; see --list-types or add it with --types\n",
                                 type_name);
        return kExitError;
      }
    }

    const resolver::EchoFilter filter = resolver::make_echo_filter(channel_regex, type_name);
    const resolver::LcmJsonDecoder decoder(registry);

    if (!log_path.empty()) {
      resolver::echo_log_file(log_path, decoder, filter, limit, print_line);
      return std::fflush(stdout) == 0 ? 0 : kExitError;
    }

    lcm::LCM lcm(lcm_url);
    std::optional<std::chrono::milliseconds> timeout;
    if (timeout_s) timeout = std::chrono::milliseconds(static_cast<std::int64_t>(*timeout_s * 1000.0));
    resolver::LiveEcho live(lcm, decoder, filter, [](const std::string& line) {
      print_line(line);
      std::fflush(stdout);  // live output is watched or piped: do not sit in a buffer
    });
    const auto result = live.run(count, timeout);
    if (!result.error.empty()) {
      std::cerr << "resolver-echo: --lcm " << lcm_url << ": " << result.error << '\n';
      return kExitError;
    }
    if (count && result.emitted < *count) {
      std::cerr << fmt::format("resolver-echo: --timeout {} s expired after {} of --count {} messages\n", *timeout_s,
                               result.emitted, *count);
      return kExitTimeout;
    }
    return 0;
  } catch (const resolver::EventLogError& e) {
    std::fflush(stdout);
    std::cerr << "resolver-echo: " << e.what() << '\n';
  } catch (const resolver::LcmParseError& e) {
    std::cerr << "resolver-echo: " << e.what() << '\n';
  } catch (const std::exception& e) {
    std::cerr << "resolver-echo: " << e.what() << '\n';
  }
  return kExitError;
}
