#include "daemon/service/program_version.h"

// Generated at build time into the build tree (cmake/Version.cmake); only
// this file includes it, so a new commit recompiles one file.
#include "resolver_version_info.h"

namespace resolver {

std::string version_line(std::string_view program) {
  std::string line(program);
  line += ' ';
  line += version_info::kProjectVersion;
  line += " (git ";
  line += version_info::kGitDescription;
  line += ')';
  return line;
}

}  // namespace resolver
