// The default bench DBC (proto/resolver_bench.dbc), compiled into resolverd.
#pragma once

#include <string_view>

namespace resolver {

/// Text of proto/resolver_bench.dbc as of the build.
std::string_view embedded_bench_dbc();

}  // namespace resolver
