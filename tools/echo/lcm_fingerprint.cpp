#include "tools/echo/lcm_fingerprint.h"

#include <vector>

#include <fmt/format.h>

namespace resolver {

namespace {

// lcm-gen works on a signed int64 and a (signed on x86) char: v = ((v<<8) ^ (v>>55)) + c,
// with an arithmetic right shift. Unsigned arithmetic reproduces the same bits
// without signed-overflow UB; the shift's sign fill is added by hand.
std::uint64_t hash_update(std::uint64_t v, std::uint64_t byte) {
  const auto c = static_cast<std::int8_t>(static_cast<std::uint8_t>(byte & 0xFFu));
  std::uint64_t shifted = v >> 55;
  if ((v >> 63) != 0) shifted |= ~std::uint64_t{0} << 9;
  return ((v << 8) ^ shifted) + static_cast<std::uint64_t>(static_cast<std::int64_t>(c));
}

std::uint64_t hash_string_update(std::uint64_t v, const std::string& s) {
  v = hash_update(v, s.size());
  for (char ch : s) v = hash_update(v, static_cast<std::uint8_t>(ch));
  return v;
}

std::uint64_t rotate_left_1(std::uint64_t h) { return (h << 1) + ((h >> 63) & 1u); }

std::uint64_t fingerprint_recursive(const LcmStruct& s, const LcmTypeLookup& lookup,
                                    std::vector<const LcmStruct*>& path) {
  for (const LcmStruct* on_path : path) {
    if (on_path == &s) return 0;
  }
  path.push_back(&s);
  std::uint64_t hash = lcm_base_hash(s);
  for (const auto& m : s.members) {
    if (m.primitive) continue;
    const LcmStruct* nested = lookup(m.type_name);
    if (nested == nullptr) {
      throw LcmTypeError(fmt::format("type '{}' (member '{}' of '{}', {}) is not defined; add its .lcm file "
                                     "(resolver-echo --types DIR)",
                                     m.type_name, m.name, s.full_name(), s.source));
    }
    hash += fingerprint_recursive(*nested, lookup, path);
  }
  path.pop_back();
  return rotate_left_1(hash);
}

}  // namespace

std::uint64_t lcm_base_hash(const LcmStruct& s) {
  std::uint64_t v = 0x12345678;
  for (const auto& m : s.members) {
    v = hash_string_update(v, m.name);
    if (m.primitive) v = hash_string_update(v, m.type_name);
    v = hash_update(v, m.dimensions.size());
    for (const auto& d : m.dimensions) {
      // lcm-gen's dimension modes: LCM_CONST = 0, LCM_VAR = 1.
      v = hash_update(v, d.is_variable ? 1u : 0u);
      v = hash_string_update(v, d.size_text);
    }
  }
  return v;
}

std::uint64_t lcm_fingerprint(const LcmStruct& s, const LcmTypeLookup& lookup) {
  std::vector<const LcmStruct*> path;
  return fingerprint_recursive(s, lookup, path);
}

}  // namespace resolver
