// Throughput of the hot path: decoding every signal of bench frames through the
// DBC codec, as the daemon does per frame. Run: build/bin/bench_dbc_codec
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>
#include <vector>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/bench_layout.h"

namespace {

using resolver::CanFrame;
namespace dbc = resolver::dbc;

void BM_DecodeBenchFrames(benchmark::State& state) {
  const dbc::Database db = dbc::load_dbc_file(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc");
  std::mt19937 rng(1);
  std::vector<CanFrame> frames;
  for (int i = 0; i < 1024; ++i) {
    const auto c = static_cast<std::uint8_t>(i);
    frames.push_back(resolver::bench::encode_resolver_sample(0, c, static_cast<std::int16_t>(rng()),
                                                             static_cast<std::int16_t>(rng()),
                                                             static_cast<std::uint16_t>(rng())));
    frames.push_back(resolver::bench::encode_phase_currents(0, c, static_cast<std::int16_t>(rng()),
                                                            static_cast<std::int16_t>(rng()),
                                                            static_cast<std::int16_t>(rng())));
  }
  const dbc::Message* msgs[2] = {db.find_message(0x100, false), db.find_message(0x101, false)};
  std::size_t i = 0;
  for (auto _ : state) {
    const CanFrame& f = frames[i];
    const dbc::Message& m = *msgs[i & 1U];
    const std::span<const std::uint8_t> d(f.data.data(), f.len);
    double acc = 0.0;
    for (const dbc::Signal& s : m.signals) acc += dbc::decode_physical(s, d);
    benchmark::DoNotOptimize(acc);
    i = (i + 1) % frames.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_DecodeBenchFrames);

}  // namespace

BENCHMARK_MAIN();
