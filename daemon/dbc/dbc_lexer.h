// Tokenizer for DBC text (internal to the parser).
//
// DBC is mostly token based (CM_, VAL_, BA_... end with ';', strings may span
// lines) but partly line based (BO_/SG_/BU_ lists end at the end of the line),
// so every token carries the line it starts and ends on and its column. The
// lexer never fails: characters it does not know become kBad tokens, which the
// parser reports with their line when it meets one where it expected something
// else (and never meets when it skips an unknown statement line-wise).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace resolver::dbc::detail {

enum class TokenKind : std::uint8_t {
  kIdent,   ///< [A-Za-z_][A-Za-z0-9_]*  (keywords too)
  kNumber,  ///< [+-]?digits[.digits][e[+-]digits]
  kString,  ///< "..." with \" and \\ unescaped; text is the content
  kPunct,   ///< one of : | @ + - ( ) [ ] , ;
  kEnd,     ///< end of input
  kBad,     ///< unknown character or unterminated string; text says which
};

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;
  std::size_t line = 1;      ///< 1-based line of the first character
  std::size_t end_line = 1;  ///< line of the last character (differs for multi-line strings)
  std::size_t column = 0;    ///< 0-based column of the first character
  std::size_t offset = 0;    ///< byte offset of the first character

  [[nodiscard]] bool is_punct(char c) const { return kind == TokenKind::kPunct && text.size() == 1 && text[0] == c; }
  [[nodiscard]] bool is_ident(std::string_view word) const { return kind == TokenKind::kIdent && text == word; }
  /// "'BO_'", "string \"abc\"", "end of file": for "expected X, found Y" messages.
  [[nodiscard]] std::string describe() const;
};

class Lexer {
 public:
  explicit Lexer(std::string_view text);

  /// The next token without consuming it.
  const Token& peek();
  /// Consumes and returns the next token.
  Token next();
  /// Drops everything up to and including the end of the current line (the
  /// line the last consumed token ended on); a string opened on it runs on.
  void skip_line();
  /// Line the last consumed token ended on (1 before any).
  [[nodiscard]] std::size_t line() const { return last_line_; }

 private:
  Token lex();
  void skip_space();
  void lex_string(Token& t);
  void lex_number(Token& t);

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;         // line at pos_
  std::size_t line_start_ = 0;   // offset of the first character of line_
  std::size_t last_line_ = 1;
  bool has_peek_ = false;
  Token peek_;
};

}  // namespace resolver::dbc::detail
