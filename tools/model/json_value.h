// A minimal strict JSON reader: what resolver-model fleet --summarize reads its own
// unit.json files back with. A copy of tests/unit/echo/json_test_parser (kept there
// separately: the echo tests want a parser independent of the code they check).
// Numbers keep their text.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace resolver::json {

struct JsonMember;

struct Json {
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };
  Kind kind = Kind::kNull;
  bool boolean = false;
  std::string text;  ///< number text or decoded string
  std::vector<Json> items;
  /// In document order. Not a std::pair<std::string, Json>: a pair needs Json complete,
  /// which only GCC's library lets pass inside Json itself (clang refuses it).
  std::vector<JsonMember> members;

  bool is_null() const { return kind == Kind::kNull; }
  double number() const;
  long long integer() const;
  /// The member called `key`; throws std::out_of_range if absent.
  const Json& operator[](std::string_view key) const;
  const Json& operator[](std::size_t index) const { return items.at(index); }
  bool has(std::string_view key) const;
  std::vector<std::string> keys() const;
};

struct JsonMember {
  std::string name;
  Json value;
};

/// Parses exactly one JSON value filling `text`; throws std::runtime_error
/// (with the offset) on anything that is not strict JSON.
Json parse_json(std::string_view text);

}  // namespace resolver::json
