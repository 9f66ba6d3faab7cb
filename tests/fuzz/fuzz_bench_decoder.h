// The bench layout's FrameDecoder (proto/resolver_bench.dbc and the default
// signal map), built once per fuzz process, as resolverd builds it with no
// config. Test code only; needs RESOLVER_BENCH_DBC (tests/fuzz/CMakeLists.txt).
#pragma once

#include <memory>
#include <stdexcept>
#include <variant>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_decoder.h"

#ifndef RESOLVER_BENCH_DBC
#error "RESOLVER_BENCH_DBC must name proto/resolver_bench.dbc"
#endif

namespace resolver::fuzz {

inline std::shared_ptr<const FrameDecoder> bench_decoder() {
  static const std::shared_ptr<const FrameDecoder> decoder = [] {
    auto loaded = dbc::load_dbc_file(RESOLVER_BENCH_DBC);
    if (const auto* error = std::get_if<dbc::DbcError>(&loaded)) {
      throw std::runtime_error("fuzz: cannot load the bench DBC: " + error->what());
    }
    auto db = std::make_shared<const dbc::Database>(std::get<dbc::Database>(std::move(loaded)));
    return std::make_shared<const FrameDecoder>(db, SignalMap::bench_default());
  }();
  return decoder;
}

}  // namespace resolver::fuzz
