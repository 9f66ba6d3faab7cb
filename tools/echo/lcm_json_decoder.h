// LCM message bytes -> JSON, driven by the type descriptions in a registry.
//
// Wire format (LCM spec): an 8-byte big-endian fingerprint, then the members in
// declaration order; integers and floats big-endian; boolean and byte one byte;
// string = int32 length (including a NUL) + bytes + NUL; arrays element by
// element, outer dimension first, a variable dimension's length being the value
// of an earlier integer member; nested structs inline without a fingerprint.
//
// The decoder never throws on bad bytes: problems come back in
// DecodedMessage::error with the member and byte offset.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tools/echo/lcm_type_registry.h"

namespace resolver {

/// One numeric leaf of a message, for tables (resolver-echo --csv): members of
/// nested structs joined with '_' ("pose_x"), array elements numbered from 0
/// ("value_0", "value_1"; "m_1_2" in two dimensions).
struct NumericField {
  std::string name;
  /// Integers exactly, floating point in the shortest text that reads back to the
  /// same value, NaN / Inf / -Inf as MATLAB and pandas read them, booleans 1 / 0.
  std::string text;
};

struct DecodedMessage {
  /// The matching type, or nullptr when the fingerprint is unknown (or the
  /// message is too short to hold one).
  const LcmStruct* type = nullptr;
  /// The message's first 8 bytes, big-endian (0 when shorter than 8 bytes).
  std::uint64_t fingerprint = 0;
  /// JSON value of the top-level member named "utime", if the type has one.
  std::optional<std::string> utime_json;
  /// `"name":value` pairs joined by commas, every member except the top-level
  /// utime, in declaration order; nested structs as objects, arrays as arrays.
  std::string fields_json;
  /// Empty on success; otherwise what went wrong and where.
  std::string error;
  /// With decode(data, true): every numeric member (integers, floats, booleans,
  /// bytes) except the top-level utime, in declaration order. Strings are text,
  /// not numbers, and are left out. Empty when `error` is set.
  std::vector<NumericField> numbers;
};

class LcmJsonDecoder {
 public:
  /// Keeps a reference: `registry` must outlive the decoder.
  explicit LcmJsonDecoder(const LcmTypeRegistry& registry) : registry_(registry) {}

  /// Decodes one whole message (fingerprint included). Bytes after the last
  /// member are ignored, as LCM's generated decoders do. `with_numbers` also
  /// fills DecodedMessage::numbers.
  DecodedMessage decode(std::span<const std::uint8_t> data, bool with_numbers = false) const;

 private:
  const LcmTypeRegistry& registry_;
};

}  // namespace resolver
