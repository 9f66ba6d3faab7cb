// Fuzz target: parse_daemon_config (daemon/app/daemon_config.h), then the
// frame decoder built from the resulting signal map over the bench DBC, as
// resolverd does at start and on SIGHUP.
//
// Properties: the only exception parse_daemon_config may throw is ConfigError
// (resolverd's main catches exactly that; anything else would terminate the
// daemon), with a message that names the source; the only one FrameDecoder may
// throw is InputError (usage), naming the source too. An accepted config keeps
// the invariants its validation promises (decimations, revolutions and
// max_counter_delta >= 1, rd_bits 1..16, sample_rate_hz >= 0).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/app/daemon_config.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_decoder.h"
#include "tests/fuzz/fuzz_support.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc"
#endif

namespace {

std::shared_ptr<const resolver::dbc::Database> bench_db() {
  static const std::shared_ptr<const resolver::dbc::Database> db = [] {
    // A failure throws InputError or IoError naming the file: the fuzzer stops on it.
    return std::make_shared<const resolver::dbc::Database>(resolver::dbc::load_dbc_file(RESOLVER_BENCH_DBC));
  }();
  return db;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string source = "fuzz.toml";
  resolver::DaemonConfig config;
  try {
    config = resolver::parse_daemon_config(resolver::fuzz::as_text(data, size), source);
  } catch (const resolver::ConfigError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(what.rfind(source, 0) == 0, "ConfigError does not start with the source name");
    return 0;
  }
  FUZZ_CHECK(config.angle_decimation >= 1 && config.dq_decimation >= 1, "accepted decimation < 1");
  FUZZ_CHECK(config.ripple_revolutions >= 1, "accepted ripple_revolutions < 1");
  FUZZ_CHECK(config.max_counter_delta >= 1, "accepted max_counter_delta < 1");
  FUZZ_CHECK(config.bench.rd_bits >= 1 && config.bench.rd_bits <= 16, "accepted rd_bits outside 1..16");
  FUZZ_CHECK(config.bench.sample_rate_hz >= 0.0, "accepted a negative or NaN sample_rate_hz");
  try {
    const resolver::FrameDecoder decoder(bench_db(), config.signal_map, resolver::Where::at_file(source));
    (void)decoder.mapped_roles();
  } catch (const resolver::InputError& e) {
    // A signal map that does not fit the bench DBC: resolverd reports it and exits 2.
    FUZZ_CHECK(e.fault() == resolver::Fault::kUsage, "FrameDecoder's InputError is not a usage fault");
    FUZZ_CHECK(std::string(e.what()).rfind(source, 0) == 0, "FrameDecoder's InputError does not start with the source");
  }
  return 0;
}
