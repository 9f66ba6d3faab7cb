// Descriptions of LCM message types, as read from .lcm files.
//
// resolver-echo decodes messages generically: instead of linking the C++ code
// lcm-gen writes, it parses the .lcm definitions (lcm_type_parser.h) into the
// plain structs below, computes each type's fingerprint (lcm_fingerprint.h) and
// walks the description while decoding bytes (lcm_json_decoder.h). A new type
// therefore needs no code, only its .lcm file.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace resolver {

/// LCM's built-in types. Unsigned types do not exist in LCM (no Java equivalent).
enum class LcmPrimitive { kInt8, kInt16, kInt32, kInt64, kFloat, kDouble, kString, kBoolean, kByte };

/// The primitive named `name` ("int8_t", "double", "boolean", ...), or nullopt.
std::optional<LcmPrimitive> lcm_primitive_from_name(std::string_view name);

/// Encoded size in bytes of a fixed-size primitive; strings return their
/// smallest encoding (4-byte length + NUL = 5).
std::size_t lcm_primitive_min_size(LcmPrimitive p);

/// One array dimension: `[3]` (fixed) or `[num_x]` (length held by an earlier
/// integer member of the same struct).
struct LcmDimension {
  bool is_variable = false;
  /// The size exactly as written in the .lcm file ("3", "0x3" or "num_x"): the
  /// fingerprint hashes this text, not the number.
  std::string size_text;
  /// Element count of a fixed dimension (0 when is_variable).
  std::int64_t fixed_size = 0;
};

struct LcmMember {
  std::string name;
  /// "int32_t", "string", ... for primitives; the fully qualified
  /// "package.name" for structs (a bare name gets the file's package, as lcm-gen does).
  std::string type_name;
  /// Set for primitive members, empty for nested structs.
  std::optional<LcmPrimitive> primitive;
  /// Outermost first; empty for a scalar.
  std::vector<LcmDimension> dimensions;
};

/// `const double PI = 3.14;` — part of the type's API but not of its encoding.
struct LcmConstant {
  std::string type_name;
  std::string name;
  std::string value_text;
};

struct LcmStruct {
  std::string package;  ///< "" when the file has no package directive
  std::string name;     ///< short name, e.g. "angle_t"
  std::vector<LcmMember> members;
  std::vector<LcmConstant> constants;
  std::string source;   ///< where it was defined, for error messages ("angle_t.lcm:5")

  /// "package.name", or just "name" without a package.
  std::string full_name() const;
  /// The member called `member_name`, or nullptr.
  const LcmMember* find_member(std::string_view member_name) const;
};

}  // namespace resolver
