// The bench layout's FrameDecoder (proto/resolver_bench.dbc and the default
// signal map), built once per fuzz process, as resolverd builds it with no
// config. Test code only; needs RESOLVER_BENCH_DBC (tests/fuzz/CMakeLists.txt).
#pragma once

#include <memory>
#include <stdexcept>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_decoder.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc"
#endif

namespace resolver::fuzz {

inline std::shared_ptr<const FrameDecoder> bench_decoder() {
  static const std::shared_ptr<const FrameDecoder> decoder = [] {
    // A failure throws InputError or IoError naming the file: the fuzzer stops on it.
    auto db = std::make_shared<const dbc::Database>(dbc::load_dbc_file(RESOLVER_BENCH_DBC));
    return std::make_shared<const FrameDecoder>(db, SignalMap::bench_default());
  }();
  return decoder;
}

}  // namespace resolver::fuzz
