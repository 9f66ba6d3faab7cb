// The one line every program prints for --version:
//   "resolverd 0.1.0 (git 7d43eb5-dirty)"
// 0.1.0 is CMake's project(... VERSION); the git part is `git describe
// --always --dirty` of the source tree at build time, "unknown" when it was
// built outside a git checkout (cmake/Version.cmake). help2man reads this
// line into the man pages' footer.
//
// Use: app.set_version_flag("--version", resolver::version_line("resolverd"));
#pragma once

#include <string>
#include <string_view>

namespace resolver {

/// "PROGRAM VERSION (git DESCRIPTION)". Cannot fail.
std::string version_line(std::string_view program);

}  // namespace resolver
