#include "tools/echo/lcm_json_decoder.h"

#include <bit>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "drivers/text/json_string.h"
#include "tools/echo/json_writer.h"

namespace resolver {

namespace {

// Nested structs deeper than this are certainly a corrupt message of a
// recursive type, not data; stop before the stack does.
constexpr int kMaxNesting = 64;
// Elements that encode to zero bytes (empty structs) cannot be bounded by the
// message size, so their count is capped instead.
constexpr std::int64_t kMaxZeroSizeElements = std::int64_t{1} << 20;

// A decoding problem. `path` grows outward as the exception passes through
// members and array elements, so the final message names e.g. "value[3]".
struct DecodeFailure {
  std::string path;
  std::string reason;
};

void prepend_member(DecodeFailure& f, const std::string& name) {
  if (!f.path.empty() && f.path.front() != '[') f.path.insert(0, ".");
  f.path.insert(0, name);
}

class Decoder {
 public:
  Decoder(const LcmTypeRegistry& registry, std::span<const std::uint8_t> data, std::size_t start,
          std::vector<NumericField>* numbers)
      : registry_(registry), data_(data), pos_(start), numbers_(numbers) {}

  // Writes the members of `s` as "name":value pairs. When `utime_out` is set
  // (top level), the member named utime goes there instead.
  void decode_struct_fields(const LcmStruct& s, std::string& out, std::optional<std::string>* utime_out, int depth) {
    if (depth > kMaxNesting) {
      throw DecodeFailure{"", fmt::format("structs nested deeper than {} levels; the message is corrupt", kMaxNesting)};
    }
    // Values of scalar integer members, for the variable dimensions that follow.
    std::vector<std::int64_t> integers(s.members.size(), 0);
    bool first = true;
    for (std::size_t i = 0; i < s.members.size(); ++i) {
      const LcmMember& m = s.members[i];
      std::string value;
      const bool top_utime = utime_out != nullptr && m.name == "utime";
      const std::size_t name_mark = number_name_.size();
      if (!number_name_.empty()) number_name_.push_back('_');
      number_name_ += m.name;
      const std::size_t numbers_mark = numbers_ != nullptr ? numbers_->size() : 0;
      try {
        decode_dimension(s, m, integers, 0, value, integers[i], depth);
      } catch (DecodeFailure& f) {
        prepend_member(f, m.name);
        throw;
      }
      number_name_.resize(name_mark);
      if (top_utime) {
        // The message's time: a table's time column, not one of its numbers.
        if (numbers_ != nullptr) numbers_->resize(numbers_mark);
        *utime_out = std::move(value);
        continue;
      }
      if (!first) out.push_back(',');
      first = false;
      text::append_json_string(out, m.name);
      out.push_back(':');
      out += value;
    }
  }

 private:
  std::span<const std::uint8_t> take(std::size_t n) {
    if (n > data_.size() - pos_) {
      throw DecodeFailure{"", fmt::format("needs {} byte(s) at byte offset {} but the message ends at {}", n, pos_,
                                          data_.size())};
    }
    const auto bytes = data_.subspan(pos_, n);
    pos_ += n;
    return bytes;
  }

  std::uint64_t read_be(std::size_t n) {
    std::uint64_t v = 0;
    for (std::uint8_t b : take(n)) v = (v << 8) | b;
    return v;
  }

  std::int64_t dimension_length(const LcmStruct& s, const LcmMember& m, const std::vector<std::int64_t>& integers,
                                std::size_t dim) const {
    const LcmDimension& d = m.dimensions[dim];
    if (!d.is_variable) return d.fixed_size;
    for (std::size_t k = 0; k < s.members.size(); ++k) {
      if (s.members[k].name == d.size_text) return integers[k];
    }
    return 0;  // unreachable: the parser only accepts earlier members
  }

  // Smallest number of bytes one element of `type_name` can encode to.
  std::size_t min_size(const LcmMember& m, std::vector<const LcmStruct*>& path) const {
    std::size_t elem = 0;
    if (m.primitive) {
      elem = lcm_primitive_min_size(*m.primitive);
    } else if (const LcmStruct* nested = registry_.find_by_name(m.type_name)) {
      for (const LcmStruct* p : path) {
        if (p == nested) return 0;
      }
      path.push_back(nested);
      for (const auto& inner : nested->members) elem += min_size(inner, path);
      path.pop_back();
    }
    for (const auto& d : m.dimensions) {
      if (d.is_variable) return 0;
      elem *= static_cast<std::size_t>(d.fixed_size);
    }
    return elem;
  }

  std::size_t min_element_size(const LcmMember& m, std::size_t dim) const {
    LcmMember inner = m;
    inner.dimensions.erase(inner.dimensions.begin(), inner.dimensions.begin() + static_cast<std::ptrdiff_t>(dim + 1));
    std::vector<const LcmStruct*> path;
    return min_size(inner, path);
  }

  void decode_dimension(const LcmStruct& s, const LcmMember& m, const std::vector<std::int64_t>& integers,
                        std::size_t dim, std::string& out, std::int64_t& integer_value, int depth) {
    if (dim == m.dimensions.size()) {
      decode_scalar(m, out, integer_value, depth);
      return;
    }
    const std::int64_t count = dimension_length(s, m, integers, dim);
    if (count < 0) {
      throw DecodeFailure{"", fmt::format("array length '{}' is negative ({}); the message is corrupt",
                                          m.dimensions[dim].size_text, count)};
    }
    const std::size_t elem = min_element_size(m, dim);
    const std::size_t left = data_.size() - pos_;
    const bool too_long = elem == 0 ? count > kMaxZeroSizeElements
                                    : static_cast<std::uint64_t>(count) > left / elem;
    if (too_long) {
      throw DecodeFailure{"", fmt::format("array length {} needs at least {} bytes at byte offset {} but only {} "
                                          "remain; the message is truncated or corrupt",
                                          count, elem * static_cast<std::size_t>(count), pos_, left)};
    }
    out.push_back('[');
    std::int64_t ignored = 0;
    const std::size_t name_mark = number_name_.size();
    for (std::int64_t i = 0; i < count; ++i) {
      if (i > 0) out.push_back(',');
      number_name_.resize(name_mark);
      number_name_ += fmt::format("_{}", i);
      try {
        decode_dimension(s, m, integers, dim + 1, out, ignored, depth);
      } catch (DecodeFailure& f) {
        if (!f.path.empty() && f.path.front() != '[') f.path.insert(0, ".");
        f.path.insert(0, fmt::format("[{}]", i));
        throw;
      }
    }
    number_name_.resize(name_mark);
    out.push_back(']');
  }

  // A numeric leaf for the table (NumericField), when numbers are wanted.
  template <typename T>
  void number(T value) {
    if (numbers_ == nullptr) return;
    std::string text;
    if constexpr (std::is_floating_point_v<T>) {
      if (std::isnan(value)) text = "NaN";
      else if (std::isinf(value)) text = value > 0 ? "Inf" : "-Inf";
      else append_json_number(text, value);
    } else {
      append_json_number(text, static_cast<std::int64_t>(value));
    }
    numbers_->push_back({number_name_, std::move(text)});
  }

  void decode_scalar(const LcmMember& m, std::string& out, std::int64_t& integer_value, int depth) {
    if (!m.primitive) {
      const LcmStruct* nested = registry_.find_by_name(m.type_name);
      if (nested == nullptr) {
        throw DecodeFailure{"", fmt::format("type '{}' is not defined; add its .lcm file with --types", m.type_name)};
      }
      out.push_back('{');
      decode_struct_fields(*nested, out, nullptr, depth + 1);
      out.push_back('}');
      return;
    }
    switch (*m.primitive) {
      case LcmPrimitive::kInt8:
        integer_value = static_cast<std::int8_t>(read_be(1));
        append_json_number(out, integer_value);
        number(integer_value);
        return;
      case LcmPrimitive::kInt16:
        integer_value = static_cast<std::int16_t>(read_be(2));
        append_json_number(out, integer_value);
        number(integer_value);
        return;
      case LcmPrimitive::kInt32:
        integer_value = static_cast<std::int32_t>(read_be(4));
        append_json_number(out, integer_value);
        number(integer_value);
        return;
      case LcmPrimitive::kInt64:
        integer_value = static_cast<std::int64_t>(read_be(8));
        append_json_number(out, integer_value);
        number(integer_value);
        return;
      case LcmPrimitive::kFloat: {
        const float v = std::bit_cast<float>(static_cast<std::uint32_t>(read_be(4)));
        append_json_number(out, v);
        number(v);
        return;
      }
      case LcmPrimitive::kDouble: {
        const double v = std::bit_cast<double>(read_be(8));
        append_json_number(out, v);
        number(v);
        return;
      }
      case LcmPrimitive::kBoolean: {
        const bool v = read_be(1) != 0;
        out += v ? "true" : "false";
        number(v ? 1 : 0);
        return;
      }
      case LcmPrimitive::kByte: {
        const auto v = static_cast<std::int64_t>(read_be(1));
        append_json_number(out, v);
        number(v);
        return;
      }
      case LcmPrimitive::kString: {
        const std::size_t at = pos_;
        const auto length = static_cast<std::int32_t>(read_be(4));
        if (length <= 0) {
          throw DecodeFailure{"", fmt::format("string length {} at byte offset {} is invalid (it counts the "
                                              "terminating NUL, so it is at least 1); the message is corrupt",
                                              length, at)};
        }
        const auto bytes = take(static_cast<std::size_t>(length));
        // The last byte is the NUL terminator, not text.
        text::append_json_string(out, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size() - 1));
        return;
      }
    }
  }

  const LcmTypeRegistry& registry_;
  std::span<const std::uint8_t> data_;
  std::size_t pos_;
  std::vector<NumericField>* numbers_;  ///< nullptr: JSON only
  std::string number_name_;             ///< the leaf being decoded, as NumericField::name
};

}  // namespace

DecodedMessage LcmJsonDecoder::decode(std::span<const std::uint8_t> data, bool with_numbers) const {
  DecodedMessage result;
  if (data.size() < 8) {
    result.error = fmt::format("message is {} byte(s), shorter than the 8-byte type fingerprint", data.size());
    return result;
  }
  for (std::size_t i = 0; i < 8; ++i) result.fingerprint = (result.fingerprint << 8) | data[i];
  result.type = registry_.find_by_fingerprint(result.fingerprint);
  if (result.type == nullptr) {
    result.error = fmt::format("unknown fingerprint {}", hex64(result.fingerprint));
    return result;
  }
  Decoder decoder(registry_, data, 8, with_numbers ? &result.numbers : nullptr);
  try {
    decoder.decode_struct_fields(*result.type, result.fields_json, &result.utime_json, 0);
  } catch (const DecodeFailure& f) {
    result.fields_json.clear();
    result.utime_json.reset();
    result.numbers.clear();
    result.error = f.path.empty() ? f.reason
                                  : fmt::format("member '{}' of {}: {}", f.path, result.type->full_name(), f.reason);
  }
  return result;
}

}  // namespace resolver
