// A set of LCM types, indexed by name and by fingerprint: what the decoder
// consults to turn "first 8 bytes of a message" into "how to read the rest".
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/echo/lcm_type.h"

namespace resolver {

class LcmTypeRegistry {
 public:
  /// A registry holding the embedded proto/resolver types.
  /// Throws LcmParseError if an embedded file does not parse (a build bug).
  static LcmTypeRegistry with_embedded_types();

  /// Parses one .lcm text and adds its structs. A struct whose full name is
  /// already known replaces the earlier definition (so --types can override the
  /// embedded ones). Throws LcmParseError; the registry is unchanged then.
  void add_text(std::string_view text, std::string_view source_name);

  /// Adds every *.lcm file in `dir` (not recursive), in name order.
  /// Throws LcmParseError if the directory cannot be read or a file does not parse.
  void add_directory(const std::filesystem::path& dir);

  const LcmStruct* find_by_name(std::string_view full_name) const;
  const LcmStruct* find_by_fingerprint(std::uint64_t fingerprint) const;
  /// The fingerprint of a registered struct; nullopt when a nested type is missing.
  std::optional<std::uint64_t> fingerprint_of(std::string_view full_name) const;

  /// All registered structs, by full name.
  std::vector<const LcmStruct*> types() const;
  /// One message per struct whose fingerprint cannot be computed (a nested
  /// type is missing); such structs cannot be decoded.
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  void rebuild_index();

  std::map<std::string, LcmStruct, std::less<>> by_name_;
  std::map<std::uint64_t, const LcmStruct*> by_fingerprint_;
  std::map<std::string, std::uint64_t, std::less<>> fingerprint_by_name_;
  std::vector<std::string> problems_;
};

}  // namespace resolver
