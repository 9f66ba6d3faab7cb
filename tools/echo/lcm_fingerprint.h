// LCM type fingerprints, computed exactly as lcm-gen computes them, so a
// message's first 8 bytes identify which .lcm definition decodes it.
//
// Two stages (see lcm-gen's lcmgen.c and the generated _computeHash()):
//  1. base hash of one struct: start at 0x12345678 and fold in, per member, its
//     name, its type name if primitive (nested structs contribute through stage
//     2 instead, so renaming a struct keeps its fingerprint), the number of
//     dimensions and each dimension's mode and size text. Struct name and
//     constants are not part of it.
//  2. fingerprint: base hash + the stage-2 value of every nested-struct member
//     (once per member, duplicates included), then rotated left by one bit.
//     A type already on the path being computed contributes 0, which makes
//     recursive types finite.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

#include "tools/echo/lcm_type.h"

namespace resolver {

class LcmTypeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Stage 1: the constant lcm-gen writes into the generated code.
std::uint64_t lcm_base_hash(const LcmStruct& s);

/// Finds a struct by fully qualified name; returns nullptr if unknown.
using LcmTypeLookup = std::function<const LcmStruct*(const std::string& full_name)>;

/// Stage 2: the fingerprint getHash() returns and encode() writes (big-endian)
/// in front of every message. Throws LcmTypeError naming the member if a nested
/// type cannot be found by `lookup`.
std::uint64_t lcm_fingerprint(const LcmStruct& s, const LcmTypeLookup& lookup);

}  // namespace resolver
