// The project's own .lcm files (proto/resolver/*.lcm), compiled into the binary
// so resolver-echo decodes the project's messages with no files at run time.
// The definition is generated at build time by embed_lcm_files.cmake.
#pragma once

#include <span>
#include <string_view>

namespace resolver {

struct EmbeddedLcmFile {
  std::string_view path;  ///< relative to the repository root, e.g. "proto/resolver/angle_t.lcm"
  std::string_view text;  ///< the file's full text
};

/// Every embedded .lcm file, sorted by path.
std::span<const EmbeddedLcmFile> embedded_lcm_files();

}  // namespace resolver
