#include "tools/echo/lcm_type.h"

#include <array>
#include <utility>

namespace resolver {

namespace {
constexpr std::array<std::pair<std::string_view, LcmPrimitive>, 9> kPrimitiveNames{{
    {"int8_t", LcmPrimitive::kInt8},
    {"int16_t", LcmPrimitive::kInt16},
    {"int32_t", LcmPrimitive::kInt32},
    {"int64_t", LcmPrimitive::kInt64},
    {"float", LcmPrimitive::kFloat},
    {"double", LcmPrimitive::kDouble},
    {"string", LcmPrimitive::kString},
    {"boolean", LcmPrimitive::kBoolean},
    {"byte", LcmPrimitive::kByte},
}};
}  // namespace

std::optional<LcmPrimitive> lcm_primitive_from_name(std::string_view name) {
  for (const auto& [text, primitive] : kPrimitiveNames) {
    if (text == name) return primitive;
  }
  return std::nullopt;
}

std::size_t lcm_primitive_min_size(LcmPrimitive p) {
  switch (p) {
    case LcmPrimitive::kInt8:
    case LcmPrimitive::kBoolean:
    case LcmPrimitive::kByte:
      return 1;
    case LcmPrimitive::kInt16:
      return 2;
    case LcmPrimitive::kInt32:
    case LcmPrimitive::kFloat:
      return 4;
    case LcmPrimitive::kInt64:
    case LcmPrimitive::kDouble:
      return 8;
    case LcmPrimitive::kString:
      return 5;  // int32 length + the terminating NUL
  }
  return 1;
}

std::string LcmStruct::full_name() const {
  return package.empty() ? name : package + "." + name;
}

const LcmMember* LcmStruct::find_member(std::string_view member_name) const {
  for (const auto& m : members) {
    if (m.name == member_name) return &m;
  }
  return nullptr;
}

}  // namespace resolver
