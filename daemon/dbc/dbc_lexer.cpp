#include "daemon/dbc/dbc_lexer.h"

namespace resolver::dbc::detail {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_ident_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
bool is_ident_char(char c) { return is_ident_start(c) || is_digit(c); }
bool is_punct(char c) {
  switch (c) {
    case ':': case '|': case '@': case '+': case '-': case '(': case ')': case '[': case ']': case ',': case ';':
      return true;
    default:
      return false;
  }
}

}  // namespace

std::string Token::describe() const {
  switch (kind) {
    case TokenKind::kEnd:
      return "end of file";
    case TokenKind::kString:
      return "string \"" + text + "\"";
    case TokenKind::kBad:
      return text;
    default:
      return "'" + text + "'";
  }
}

Lexer::Lexer(std::string_view text) : text_(text) {
  // A UTF-8 byte order mark is not part of the DBC grammar.
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = line_start_ = 3;
}

const Token& Lexer::peek() {
  if (!has_peek_) {
    peek_ = lex();
    has_peek_ = true;
  }
  return peek_;
}

Token Lexer::next() {
  Token t = has_peek_ ? std::move(peek_) : lex();
  has_peek_ = false;
  last_line_ = t.end_line;
  return t;
}

void Lexer::skip_line() {
  if (has_peek_) {
    // Rewind to the peeked token; it may be on the line being skipped.
    pos_ = peek_.offset;
    line_ = peek_.line;
    line_start_ = peek_.offset - peek_.column;
    has_peek_ = false;
  }
  if (line_ > last_line_) return;  // already past the end of that line
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++pos_;
      ++line_;
      line_start_ = pos_;
      return;
    }
    if (c == '"') {
      Token scratch;
      lex_string(scratch);  // keeps line_ in step with newlines inside the string
      continue;
    }
    ++pos_;
  }
}

void Lexer::skip_space() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++pos_;
      ++line_;
      line_start_ = pos_;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++pos_;
    } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
      // Some generators emit // comments; they are not DBC, but harmless to skip.
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      return;
    }
  }
}

Token Lexer::lex() {
  skip_space();
  Token t;
  t.line = t.end_line = line_;
  t.column = pos_ - line_start_;
  t.offset = pos_;
  if (pos_ >= text_.size()) {
    t.kind = TokenKind::kEnd;
    return t;
  }
  const char c = text_[pos_];
  const char c1 = pos_ + 1 < text_.size() ? text_[pos_ + 1] : '\0';
  const char c2 = pos_ + 2 < text_.size() ? text_[pos_ + 2] : '\0';
  if (c == '"') {
    lex_string(t);
  } else if (is_ident_start(c)) {
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && is_ident_char(text_[pos_])) ++pos_;
    t.kind = TokenKind::kIdent;
    t.text = std::string(text_.substr(begin, pos_ - begin));
  } else if (is_digit(c) || (c == '.' && is_digit(c1)) ||
             ((c == '-' || c == '+') && (is_digit(c1) || (c1 == '.' && is_digit(c2))))) {
    lex_number(t);
  } else if (is_punct(c)) {
    ++pos_;
    t.kind = TokenKind::kPunct;
    t.text = std::string(1, c);
  } else {
    ++pos_;
    t.kind = TokenKind::kBad;
    const auto code = static_cast<unsigned>(static_cast<unsigned char>(c));
    t.text = (code >= 0x20 && code < 0x7F) ? "unexpected character '" + std::string(1, c) + "'"
                                           : "unexpected byte 0x" + std::string(1, "0123456789ABCDEF"[code >> 4U]) +
                                                 std::string(1, "0123456789ABCDEF"[code & 0xFU]);
  }
  t.end_line = line_;
  return t;
}

void Lexer::lex_string(Token& t) {
  const std::size_t open_line = line_;
  ++pos_;  // opening quote
  std::string out;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '"') {
      ++pos_;
      t.kind = TokenKind::kString;
      t.text = std::move(out);
      return;
    }
    if (c == '\\' && pos_ + 1 < text_.size() && (text_[pos_ + 1] == '"' || text_[pos_ + 1] == '\\')) {
      out.push_back(text_[pos_ + 1]);
      pos_ += 2;
      continue;
    }
    if (c == '\n') {
      ++line_;
      line_start_ = pos_ + 1;
    }
    if (c != '\r') out.push_back(c);
    ++pos_;
  }
  t.kind = TokenKind::kBad;
  t.text = "unterminated string (opened on line " + std::to_string(open_line) + "); add the closing '\"'";
}

void Lexer::lex_number(Token& t) {
  const std::size_t begin = pos_;
  if (text_[pos_] == '-' || text_[pos_] == '+') ++pos_;
  while (pos_ < text_.size() && is_digit(text_[pos_])) ++pos_;
  if (pos_ < text_.size() && text_[pos_] == '.') {
    ++pos_;
    while (pos_ < text_.size() && is_digit(text_[pos_])) ++pos_;
  }
  if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
    std::size_t p = pos_ + 1;
    if (p < text_.size() && (text_[p] == '+' || text_[p] == '-')) ++p;
    if (p < text_.size() && is_digit(text_[p])) {
      pos_ = p;
      while (pos_ < text_.size() && is_digit(text_[pos_])) ++pos_;
    }
  }
  t.kind = TokenKind::kNumber;
  t.text = std::string(text_.substr(begin, pos_ - begin));
}

}  // namespace resolver::dbc::detail
