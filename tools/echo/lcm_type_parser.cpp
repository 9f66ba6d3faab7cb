#include "tools/echo/lcm_type_parser.h"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <limits>
#include <optional>

#include <fmt/format.h>

namespace resolver {

namespace {

struct Token {
  std::string text;
  int line = 1;
  int column = 1;
};

bool is_punct(char c) {
  return c == '{' || c == '}' || c == '[' || c == ']' || c == ';' || c == ',' || c == '=';
}

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  const auto first = static_cast<unsigned char>(s.front());
  if (!std::isalpha(first) && s.front() != '_') return false;
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (!std::isalnum(u) && c != '_') return false;
  }
  return true;
}

// A type name is one identifier or several joined by dots ("pkg.sub.name_t").
bool is_type_name(std::string_view s) {
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = s.find('.', start);
    if (!is_identifier(s.substr(start, dot == std::string_view::npos ? dot : dot - start))) return false;
    if (dot == std::string_view::npos) return true;
    start = dot + 1;
  }
}

// Splits the text into tokens, dropping comments. Kept separate from the
// grammar so the parser below reads like the grammar in the header.
class Tokenizer {
 public:
  Tokenizer(std::string_view text, std::string_view source) : text_(text), source_(source) {}

  std::vector<Token> run() {
    std::vector<Token> tokens;
    while (skip_space_and_comments()) {
      Token tok;
      tok.line = line_;
      tok.column = column_;
      if (is_punct(text_[pos_])) {
        tok.text.assign(1, text_[pos_]);
        advance();
      } else {
        while (pos_ < text_.size() && !is_space(text_[pos_]) && !is_punct(text_[pos_]) &&
               !starts_comment()) {
          tok.text.push_back(text_[pos_]);
          advance();
        }
      }
      tokens.push_back(std::move(tok));
    }
    return tokens;
  }

 private:
  bool starts_comment() const {
    return text_[pos_] == '/' && pos_ + 1 < text_.size() &&
           (text_[pos_ + 1] == '/' || text_[pos_ + 1] == '*');
  }

  void advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    ++pos_;
  }

  // Returns false at end of text.
  bool skip_space_and_comments() {
    while (pos_ < text_.size()) {
      if (is_space(text_[pos_])) {
        advance();
      } else if (starts_comment() && text_[pos_ + 1] == '/') {
        while (pos_ < text_.size() && text_[pos_] != '\n') advance();
      } else if (starts_comment()) {
        const int line = line_;
        const int column = column_;
        advance();
        advance();
        while (pos_ < text_.size() && !(text_[pos_] == '*' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/')) {
          advance();
        }
        if (pos_ >= text_.size()) {
          throw LcmParseError(fmt::format(
              "{}:{}:{}: the /* comment is never closed; add */ where it should end", source_, line, column));
        }
        advance();
        advance();
      } else {
        return true;
      }
    }
    return false;
  }

  std::string_view text_;
  std::string_view source_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
};

std::optional<long long> parse_integer(const std::string& text) {
  if (text.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  // Base 0 accepts 10, 0x10 and 010 like lcm-gen's strtol.
  const long long v = std::strtoll(text.c_str(), &end, 0);
  if (errno != 0 || end != text.c_str() + text.size()) return std::nullopt;
  return v;
}

class Parser {
 public:
  Parser(std::vector<Token> tokens, std::string_view source) : tokens_(std::move(tokens)), source_(source) {}

  std::vector<LcmStruct> run() {
    std::vector<LcmStruct> structs;
    while (pos_ < tokens_.size()) {
      const Token& tok = next("'package' or 'struct'");
      if (tok.text == "package") {
        const Token& name = next("a package name");
        if (!is_type_name(name.text)) fail(name, fmt::format("'{}' is not a valid package name", name.text));
        package_ = name.text;
        require(";");
      } else if (tok.text == "struct") {
        structs.push_back(parse_struct(tok));
        for (std::size_t i = 0; i + 1 < structs.size(); ++i) {
          if (structs[i].name == structs.back().name && structs[i].package == structs.back().package) {
            fail(tok, fmt::format("struct '{}' is defined twice in this file", structs.back().full_name()));
          }
        }
      } else if (tok.text == "enum") {
        fail(tok, "enums are not supported by resolver-echo (they are deprecated in LCM); use an int32_t with consts");
      } else {
        fail(tok, fmt::format("expected 'package' or 'struct' but found '{}'", tok.text));
      }
    }
    return structs;
  }

 private:
  [[noreturn]] void fail(const Token& at, const std::string& what) const {
    throw LcmParseError(fmt::format("{}:{}:{}: {}", source_, at.line, at.column, what));
  }

  const Token& next(std::string_view expected) {
    if (pos_ >= tokens_.size()) {
      const Token end_token = tokens_.empty() ? Token{} : tokens_.back();
      fail(end_token, fmt::format("the file ends where {} was expected; the definition is incomplete", expected));
    }
    return tokens_[pos_++];
  }

  bool peek_is(std::string_view text) const { return pos_ < tokens_.size() && tokens_[pos_].text == text; }

  void require(std::string_view text) {
    const Token& tok = next(fmt::format("'{}'", text));
    if (tok.text != text) fail(tok, fmt::format("expected '{}' but found '{}'", text, tok.text));
  }

  std::string qualify(const std::string& type_name) const {
    if (type_name.find('.') != std::string::npos || lcm_primitive_from_name(type_name)) return type_name;
    return package_.empty() ? type_name : package_ + "." + type_name;
  }

  LcmStruct parse_struct(const Token& struct_token) {
    LcmStruct s;
    const Token& name = next("a struct name");
    if (!is_identifier(name.text)) fail(name, fmt::format("'{}' is not a valid struct name", name.text));
    s.package = package_;
    s.name = name.text;
    s.source = fmt::format("{}:{}", source_, struct_token.line);
    require("{");
    while (!peek_is("}")) {
      const Token& first = next("a member declaration or '}'");
      if (first.text == "const") {
        parse_const(s);
      } else {
        parse_members(s, first);
      }
    }
    require("}");
    return s;
  }

  void check_new_name(const LcmStruct& s, const Token& name) const {
    if (!is_identifier(name.text)) {
      fail(name, fmt::format("'{}' is not a valid member name: use letters, digits and _, not starting with a digit",
                             name.text));
    }
    bool taken = s.find_member(name.text) != nullptr;
    for (const auto& c : s.constants) taken = taken || c.name == name.text;
    if (taken) fail(name, fmt::format("member name '{}' is used twice in struct '{}'", name.text, s.name));
  }

  void parse_const(LcmStruct& s) {
    const Token& type = next("a const type");
    static constexpr std::string_view kConstTypes[] = {"int8_t", "int16_t", "int32_t", "int64_t", "float", "double"};
    bool legal = false;
    for (auto t : kConstTypes) legal = legal || t == type.text;
    if (!legal) fail(type, fmt::format("'{}' cannot be a const type; use int8_t..int64_t, float or double", type.text));
    do {
      const Token& name = next("a const name");
      check_new_name(s, name);
      require("=");
      const Token& value = next("a const value");
      check_const_value(type.text, value);
      s.constants.push_back({type.text, name.text, value.text});
    } while (consume_comma());
    require(";");
  }

  void check_const_value(const std::string& type, const Token& value) const {
    if (type == "float" || type == "double") {
      char* end = nullptr;
      (void)std::strtod(value.text.c_str(), &end);
      if (value.text.empty() || end != value.text.c_str() + value.text.size()) {
        fail(value, fmt::format("'{}' is not a floating-point value for a {} const", value.text, type));
      }
      return;
    }
    const auto v = parse_integer(value.text);
    if (!v) fail(value, fmt::format("'{}' is not an integer value for a {} const", value.text, type));
    long long lo = std::numeric_limits<long long>::min();
    long long hi = std::numeric_limits<long long>::max();
    if (type == "int8_t") { lo = -128; hi = 127; }
    if (type == "int16_t") { lo = -32768; hi = 32767; }
    if (type == "int32_t") { lo = std::numeric_limits<std::int32_t>::min(); hi = std::numeric_limits<std::int32_t>::max(); }
    if (*v < lo || *v > hi) fail(value, fmt::format("{} is out of range for a {} const", value.text, type));
  }

  bool consume_comma() {
    if (!peek_is(",")) return false;
    ++pos_;
    return true;
  }

  void parse_members(LcmStruct& s, const Token& type) {
    if (type.text == "struct" || type.text == "enum") {
      fail(type, fmt::format("nested '{}' definitions are not allowed; define it at top level and use its name",
                             type.text));
    }
    if (!is_type_name(type.text)) fail(type, fmt::format("'{}' is not a valid type name", type.text));
    LcmMember proto;
    proto.type_name = qualify(type.text);
    proto.primitive = lcm_primitive_from_name(type.text);
    do {
      const Token& name = next("a member name");
      check_new_name(s, name);
      LcmMember m = proto;
      m.name = name.text;
      while (peek_is("[")) {
        ++pos_;
        m.dimensions.push_back(parse_dimension(s));
        require("]");
      }
      s.members.push_back(std::move(m));
    } while (consume_comma());
    require(";");
  }

  LcmDimension parse_dimension(const LcmStruct& s) {
    const Token& size = next("an array size");
    LcmDimension dim;
    dim.size_text = size.text;
    if (std::isdigit(static_cast<unsigned char>(size.text.front()))) {
      const auto v = parse_integer(size.text);
      if (!v || *v <= 0 || *v > std::numeric_limits<std::int32_t>::max()) {
        fail(size, fmt::format("array size '{}' must be a positive integer", size.text));
      }
      dim.fixed_size = *v;
      return dim;
    }
    if (size.text == "]") fail(size, "an array needs a size: a positive integer or the name of an earlier integer member");
    const LcmMember* length = s.find_member(size.text);
    if (length == nullptr) {
      fail(size, fmt::format("array size '{}' is not a member declared earlier in struct '{}'; declare the length "
                             "member (int8_t..int64_t) before the array",
                             size.text, s.name));
    }
    const bool integer = length->primitive == LcmPrimitive::kInt8 || length->primitive == LcmPrimitive::kInt16 ||
                         length->primitive == LcmPrimitive::kInt32 || length->primitive == LcmPrimitive::kInt64;
    if (!integer || !length->dimensions.empty()) {
      fail(size, fmt::format("array size member '{}' must be a scalar int8_t, int16_t, int32_t or int64_t", size.text));
    }
    dim.is_variable = true;
    return dim;
  }

  std::vector<Token> tokens_;
  std::string_view source_;
  std::size_t pos_ = 0;
  std::string package_;
};

}  // namespace

std::vector<LcmStruct> parse_lcm_types(std::string_view text, std::string_view source_name) {
  return Parser(Tokenizer(text, source_name).run(), source_name).run();
}

}  // namespace resolver
