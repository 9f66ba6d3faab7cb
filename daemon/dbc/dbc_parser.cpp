#include "daemon/dbc/dbc_parser.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_lexer.h"

namespace resolver::dbc {

namespace {

using detail::Lexer;
using detail::Token;
using detail::TokenKind;

// DBC marks a 29-bit ID by setting bit 31 of the decimal ID.
constexpr std::uint32_t kExtendedFlag = 0x80000000U;
constexpr std::uint32_t kMaxStandardId = 0x7FFU;
constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFFU;
// [bytes] CAN FD maximum payload.
constexpr std::uint32_t kMaxDlc = 64;
// Vector's pseudo message that holds signals not assigned to any frame.
constexpr std::string_view kIndependentSignals = "VECTOR__INDEPENDENT_SIG_MSG";
// The DBC placeholder for "no node".
constexpr std::string_view kNoNode = "Vector__XXX";

// Statements that end with ';' and carry nothing we use.
constexpr std::string_view kIgnoredStatements[] = {
    "BA_DEF_",    "BA_DEF_DEF_",      "BA_DEF_REL_", "BA_REL_",    "BA_DEF_DEF_REL_",
    "BA_DEF_SGTYPE_", "BA_SGTYPE_", "SIG_GROUP_",     "BO_TX_BU_",   "SIG_TYPE_REF_",
    "SGTYPE_",    "SGTYPE_VAL_",  "EV_",              "ENVVAR_DATA_", "SIGTYPE_VALTYPE_", "CAT_DEF_",
    "CAT_",       "FILTER",       "BU_SG_REL_",       "BU_EV_REL_",  "BU_BO_REL_"};

// Thrown inside the parser only; parse_dbc turns it into an InputError naming the source.
struct ParseFailure {
  std::size_t line;
  std::string message;
};

std::string hex(std::uint64_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

class Parser {
 public:
  Parser(std::string_view text, std::string_view source) : lex_(text), source_(source) { db_.source = source_; }

  Database run() {
    while (true) {
      Token t = lex_.next();
      if (t.kind == TokenKind::kEnd) break;
      if (t.kind != TokenKind::kIdent) {
        fail(t.line, "expected a keyword (BO_, SG_, CM_, VAL_, ...) at the start of a statement, found " +
                         t.describe());
      }
      if (t.text != "SG_") current_.reset();
      statement(t);
    }
    check_multiplexing();
    return std::move(db_);
  }

 private:
  [[noreturn]] void fail(std::size_t line, std::string message) { throw ParseFailure{line, std::move(message)}; }

  void warn(std::size_t line, const std::string& message) {
    db_.warnings.push_back(source_ + ":" + std::to_string(line) + ": " + message);
  }

  // ---- token helpers: each names what it expected, so errors say so ----

  Token expect(TokenKind kind, std::string_view what) {
    Token t = lex_.next();
    if (t.kind != kind) fail(t.line, "expected " + std::string(what) + ", found " + t.describe());
    return t;
  }
  void expect_punct(char c, std::string_view what) {
    Token t = lex_.next();
    if (!t.is_punct(c)) {
      fail(t.line, "expected '" + std::string(1, c) + "' " + std::string(what) + ", found " + t.describe());
    }
  }
  std::string expect_ident(std::string_view what) { return expect(TokenKind::kIdent, what).text; }
  std::string expect_string(std::string_view what) { return expect(TokenKind::kString, what).text; }

  std::uint64_t expect_unsigned(std::string_view what) {
    Token t = expect(TokenKind::kNumber, what);
    std::uint64_t v = 0;
    const char* end = t.text.data() + t.text.size();
    const auto [p, ec] = std::from_chars(t.text.data(), end, v);
    if (ec != std::errc{} || p != end) {
      fail(t.line, "expected " + std::string(what) + " (an unsigned integer), found " + t.describe());
    }
    return v;
  }
  std::uint32_t expect_u32(std::string_view what) {
    const std::uint64_t v = expect_unsigned(what);
    if (v > 0xFFFFFFFFU) fail(lex_.line(), std::string(what) + " " + std::to_string(v) + " does not fit 32 bits");
    return static_cast<std::uint32_t>(v);
  }
  std::int64_t expect_integer(std::string_view what) {
    Token t = expect(TokenKind::kNumber, what);
    const char* begin = t.text.data() + (t.text[0] == '+' ? 1 : 0);
    const char* end = t.text.data() + t.text.size();
    std::int64_t v = 0;
    std::from_chars_result res = std::from_chars(begin, end, v);
    if (res.ec == std::errc::result_out_of_range && *begin != '-') {
      // Values up to 2^64-1 appear in tables of 64-bit signals; keep their bit pattern.
      std::uint64_t u = 0;
      res = std::from_chars(begin, end, u);
      v = static_cast<std::int64_t>(u);
    }
    if (res.ec != std::errc{} || res.ptr != end) fail(t.line, "expected " + std::string(what) + " (an integer), found " + t.describe());
    return v;
  }
  double expect_double(std::string_view what) {
    Token t = expect(TokenKind::kNumber, what);
    const char* begin = t.text.data() + (t.text[0] == '+' ? 1 : 0);
    const char* end = t.text.data() + t.text.size();
    double v = 0.0;
    const auto [p, ec] = std::from_chars(begin, end, v);
    if (ec != std::errc{} || p != end) fail(t.line, "expected " + std::string(what) + " (a number), found " + t.describe());
    return v;
  }

  // Consumes tokens through the next ';'.
  void skip_statement(const Token& keyword) {
    while (true) {
      Token t = lex_.next();
      if (t.is_punct(';')) return;
      if (t.kind == TokenKind::kEnd) {
        fail(keyword.line, keyword.text + " statement has no terminating ';' before the end of the file; add it");
      }
    }
  }

  void expect_semicolon(std::string_view statement) {
    expect_punct(';', "to end the " + std::string(statement) + " statement");
  }

  // ---- statements ----

  void statement(const Token& kw) {
    const std::string& k = kw.text;
    if (k == "VERSION") {
      db_.version = expect_string("the version string after VERSION");
    } else if (k == "NS_") {
      skip_new_symbols(kw);
    } else if (k == "BS_") {
      expect_punct(':', "after BS_");
      lex_.skip_line();  // optional baudrate:BTR1,BTR2, obsolete
    } else if (k == "BU_") {
      nodes(kw);
    } else if (k == "BO_") {
      message(kw);
    } else if (k == "SG_") {
      signal(kw);
    } else if (k == "CM_") {
      comment();
    } else if (k == "VAL_") {
      value_descriptions(kw);
    } else if (k == "VAL_TABLE_") {
      value_table();
    } else if (k == "SIG_VALTYPE_") {
      signal_value_type(kw);
    } else if (k == "SG_MUL_VAL_") {
      multiplexer_ranges(kw);
    } else if (k == "BA_") {
      attribute(kw);
    } else if (is_ignored(k)) {
      skip_statement(kw);
    } else {
      warn(kw.line, "unknown keyword '" + k + "'; line skipped");
      lex_.skip_line();
    }
  }

  static bool is_ignored(std::string_view k) {
    for (std::string_view s : kIgnoredStatements) {
      if (s == k) return true;
    }
    return false;
  }

  // NS_ : followed by an indented list of symbol names (which look like
  // keywords), ending at the first unindented token.
  void skip_new_symbols(const Token& kw) {
    expect_punct(':', "after NS_");
    while (true) {
      const Token& t = lex_.peek();
      if (t.kind == TokenKind::kEnd) return;
      if (t.line != kw.line && t.column == 0) return;
      if (t.is_ident("BS_") || t.is_ident("BU_") || t.is_ident("BO_")) return;
      lex_.next();
    }
  }

  void nodes(const Token& kw) {
    expect_punct(':', "after BU_");
    while (lex_.peek().kind == TokenKind::kIdent && lex_.peek().line == kw.line) db_.nodes.push_back(lex_.next().text);
  }

  void message(const Token& kw) {
    const std::uint32_t raw_id = expect_u32("the message ID after BO_");
    Message m;
    m.extended = (raw_id & kExtendedFlag) != 0;
    m.id = raw_id & ~kExtendedFlag;
    m.name = expect_ident("the message name after the ID");
    expect_punct(':', "after the message name");
    m.dlc = expect_u32("the message length (DLC) in bytes");
    m.sender = expect_ident("the sending node after the DLC (Vector__XXX if none)");

    if (m.name == kIndependentSignals) {
      // Its signals belong to no frame: parse them into a scratch message, then drop.
      scratch_ = std::move(m);
      current_ = kScratch;
      return;
    }
    if (m.dlc > kMaxDlc) {
      fail(kw.line, "message '" + m.name + "' has DLC " + std::to_string(m.dlc) + " bytes; CAN carries at most " +
                        std::to_string(kMaxDlc) + " bytes (use the byte count, not the FD DLC code)");
    }
    if (!m.extended && m.id > kMaxStandardId) {
      fail(kw.line, "message '" + m.name + "' has ID " + hex(m.id) +
                        ", too large for an 11-bit ID; for a 29-bit ID set bit 31 (write " +
                        std::to_string(static_cast<std::uint64_t>(m.id) | kExtendedFlag) + ")");
    }
    if (m.extended && m.id > kMaxExtendedId) {
      fail(kw.line, "message '" + m.name + "' has extended ID " + hex(m.id) + ", more than 29 bits");
    }
    if (const Message* first = message_by_raw_id(raw_id)) {
      // Frames of that ID would decode as whichever message a lookup finds first.
      fail(kw.line, "message '" + m.name + "' has ID " + hex(m.id) + (m.extended ? " (extended)" : "") +
                        ", already used by message '" + first->name + "' at " + source_ + ":" +
                        std::to_string(first->line) + "; each message needs its own ID: remove or renumber one");
    }
    by_raw_id_[raw_id] = db_.messages.size();
    m.line = kw.line;
    current_ = db_.messages.size();
    signal_lines_.emplace_back();
    db_.messages.push_back(std::move(m));
  }

  void signal(const Token& kw) {
    if (!current_) {
      fail(kw.line, "SG_ is not inside a message; put each SG_ line directly below its BO_ line");
    }
    Message& m = *current_ == kScratch ? scratch_ : db_.messages[*current_];
    Signal s;
    s.line = kw.line;
    s.name = expect_ident("the signal name after SG_");
    if (lex_.peek().kind == TokenKind::kIdent) multiplexer_indicator(lex_.next(), s);
    if (s.is_multiplexor) note_switch(m, s);
    expect_punct(':', "after the signal name (or its multiplexer indicator M / m<value>)");
    s.start_bit = expect_u32("the start bit");
    expect_punct('|', "between start bit and length");
    s.length = expect_u32("the signal length in bits");
    expect_punct('@', "before the byte order");
    const Token order = expect(TokenKind::kNumber, "the byte order (1 = Intel, 0 = Motorola) after '@'");
    if (order.text == "1") {
      s.order = ByteOrder::kLittleEndian;
    } else if (order.text == "0") {
      s.order = ByteOrder::kBigEndian;
    } else {
      fail(order.line, "expected the byte order 1 (Intel) or 0 (Motorola) after '@', found " + order.describe());
    }
    const Token sign = lex_.next();
    if (!sign.is_punct('+') && !sign.is_punct('-')) {
      fail(sign.line, "expected the value type '+' (unsigned) or '-' (signed) after the byte order, found " +
                          sign.describe());
    }
    s.is_signed = sign.is_punct('-');
    expect_punct('(', "before the factor");
    s.factor = expect_double("the factor");
    expect_punct(',', "between factor and offset");
    s.offset = expect_double("the offset");
    expect_punct(')', "after the offset");
    expect_punct('[', "before the minimum");
    s.minimum = expect_double("the minimum");
    expect_punct('|', "between minimum and maximum");
    s.maximum = expect_double("the maximum");
    expect_punct(']', "after the maximum");
    s.unit = expect_string("the unit string (\"\" if none)");
    receivers(kw.line, s);

    validate_signal(kw.line, m, s);
    if (m.find_signal(s.name) != nullptr) {
      fail(kw.line, "signal '" + s.name + "' is defined twice in message '" + m.name + "'; rename one");
    }
    m.signals.push_back(std::move(s));
    if (*current_ != kScratch) signal_lines_[*current_].push_back(kw.line);
  }

  void multiplexer_indicator(const Token& t, Signal& s) {
    const std::string& x = t.text;
    const auto bad = [&] {
      fail(t.line, "expected a multiplexer indicator 'M', 'm<value>' or 'm<value>M' (or ':'), found " + t.describe());
    };
    if (x == "M") {
      s.is_multiplexor = true;
      return;
    }
    if (x.size() < 2 || x[0] != 'm') bad();
    std::size_t digits_end = x.size();
    if (x.back() == 'M') {
      s.is_multiplexor = true;
      --digits_end;
    }
    std::uint64_t v = 0;
    const auto [p, ec] = std::from_chars(x.data() + 1, x.data() + digits_end, v);
    if (ec != std::errc{} || p != x.data() + digits_end || digits_end == 1) bad();
    s.multiplexed_by = v;
  }

  // BA_ "name" [BU_ node | BO_ id | SG_ id signal | EV_ name] value ;
  // Only the long names (over 32 characters) that CANdb++ and cantools keep in
  // attributes are used; every other attribute is skipped to its ';'.
  void attribute(const Token& kw) {
    const std::string name = expect_string("the attribute name string after BA_");
    if (name == "SystemSignalLongSymbol" && lex_.peek().is_ident("SG_")) {
      lex_.next();
      const std::uint32_t raw_id = expect_u32("the message ID after BA_ \"SystemSignalLongSymbol\" SG_");
      const std::string signal = expect_ident("the signal name after BA_ \"SystemSignalLongSymbol\" SG_ <id>");
      std::string long_name = expect_string("the long signal name string");
      expect_semicolon("BA_");
      if (Signal* s = signal_by(raw_id, signal)) {
        s->long_name = std::move(long_name);
      } else {
        warn(kw.line, "BA_ \"SystemSignalLongSymbol\" refers to unknown signal " + std::to_string(raw_id) + " " +
                          signal + "; its long name '" + long_name + "' is not known to the signal map");
      }
    } else if (name == "SystemMessageLongSymbol" && lex_.peek().is_ident("BO_")) {
      lex_.next();
      const std::uint32_t raw_id = expect_u32("the message ID after BA_ \"SystemMessageLongSymbol\" BO_");
      std::string long_name = expect_string("the long message name string");
      expect_semicolon("BA_");
      if (Message* m = message_by_raw_id(raw_id)) {
        m->long_name = std::move(long_name);
      } else {
        warn(kw.line, "BA_ \"SystemMessageLongSymbol\" refers to unknown message " + std::to_string(raw_id) +
                          "; its long name '" + long_name + "' is not known to the signal map");
      }
    } else {
      skip_statement(kw);
    }
  }

  // A second switch in a message (`m<n>M`, or a second `M`) is extended multiplexing.
  static void note_switch(Message& m, const Signal& s) {
    if (m.extended_mux_line != 0) return;
    if (s.multiplexed_by.has_value()) {
      m.extended_mux_line = s.line;
      m.extended_mux_note = "signal '" + s.name + "' is a second-level multiplexor (m" +
                            std::to_string(*s.multiplexed_by) + "M)";
    } else if (const Signal* first = m.multiplexor()) {
      m.extended_mux_line = s.line;
      m.extended_mux_note = "signal '" + s.name + "' is a second multiplexor (M) beside '" + first->name + "'";
    }
  }

  // SG_MUL_VAL_ id signal switch a-b[, c-d]* ;  (extended multiplexing: the
  // signal is present while `switch` is in one of the ranges). A single range
  // n-n of the top-level switch only restates `m<n>` and is accepted as simple.
  void multiplexer_ranges(const Token& kw) {
    const std::uint32_t raw_id = expect_u32("the message ID after SG_MUL_VAL_");
    const std::string name = expect_ident("the signal name after SG_MUL_VAL_ <id>");
    const std::string switch_name = expect_ident("the multiplexor switch name after SG_MUL_VAL_ <id> <signal>");
    // The ranges lex as numbers and '-' / ',' punctuation ("1-1" is the numbers 1 and -1).
    std::vector<std::string> parts;
    while (true) {
      Token t = lex_.next();
      if (t.is_punct(';')) break;
      if (t.kind == TokenKind::kEnd) fail(kw.line, "SG_MUL_VAL_ statement has no terminating ';' before the end of the file; add it");
      parts.push_back(t.text);
    }
    Message* m = message_by_raw_id(raw_id);
    Signal* s = signal_by(raw_id, name);
    if (m == nullptr || s == nullptr) {
      warn(kw.line, "SG_MUL_VAL_ refers to unknown signal " + std::to_string(raw_id) + " " + name + "; ignored");
      return;
    }
    const Signal* top = m->multiplexor();
    const bool restates_simple =
        top != nullptr && top->name == switch_name && s->multiplexed_by.has_value() && parts.size() == 2 &&
        parts[0] == std::to_string(*s->multiplexed_by) && parts[1] == "-" + std::to_string(*s->multiplexed_by);
    if (restates_simple) return;
    s->mul_val_line = kw.line;
    if (m->extended_mux_line == 0) {
      m->extended_mux_line = kw.line;
      std::string ranges;
      for (const std::string& p : parts) ranges += p;
      m->extended_mux_note = "SG_MUL_VAL_ makes signal '" + name + "' present for switch '" + switch_name +
                             "' in " + ranges;
    }
  }

  void receivers(std::size_t line, Signal& s) {
    while (true) {
      const Token& t = lex_.peek();
      // The list ends with its line, or with the file when the last line has no newline.
      if (t.line != line || t.kind == TokenKind::kEnd) return;
      if (t.is_punct(',')) {
        lex_.next();
        continue;
      }
      if (t.kind != TokenKind::kIdent) {
        fail(t.line, "expected receiver node names (comma separated) after the unit, found " + t.describe());
      }
      std::string name = lex_.next().text;
      if (name != kNoNode) s.receivers.push_back(std::move(name));
    }
  }

  void validate_signal(std::size_t line, const Message& m, const Signal& s) {
    if (s.length == 0 || s.length > detail::kMaxSignalBits) {
      fail(line, "signal '" + s.name + "' has length " + std::to_string(s.length) + "; a signal has 1..64 bits");
    }
    if (&m == &scratch_) return;  // the pseudo message has DLC 0 by design
    const detail::Span sp = detail::linear_span(s, s.length);
    const std::uint64_t first_byte = sp.first_lin >> 3U;
    const std::uint64_t last_byte = sp.last_lin >> 3U;
    if (last_byte >= m.dlc) {
      fail(line, "signal '" + s.name + "' (start bit " + std::to_string(s.start_bit) + ", " + std::to_string(s.length) +
                     " bits, " + (s.order == ByteOrder::kBigEndian ? "Motorola" : "Intel") + ") needs bytes " +
                     std::to_string(first_byte) + ".." + std::to_string(last_byte) + " but message '" + m.name +
                     "' has DLC " + std::to_string(m.dlc) + "; fix the start bit, the length or the DLC");
    }
  }

  void check_multiplexing() {
    for (std::size_t i = 0; i < db_.messages.size(); ++i) {
      const Message& m = db_.messages[i];
      if (m.multiplexor() != nullptr) continue;
      for (std::size_t j = 0; j < m.signals.size(); ++j) {
        if (m.signals[j].multiplexed_by.has_value()) {
          fail(signal_lines_[i][j], "signal '" + m.signals[j].name + "' is multiplexed (m" +
                                        std::to_string(*m.signals[j].multiplexed_by) + ") but message '" + m.name +
                                        "' has no multiplexor signal (M); mark the switch signal with M");
        }
      }
    }
  }

  Message* message_by_raw_id(std::uint32_t raw_id) {
    const auto it = by_raw_id_.find(raw_id);
    return it == by_raw_id_.end() ? nullptr : &db_.messages[it->second];
  }

  // CM_ [BU_ node | BO_ id | SG_ id signal | EV_ name] "text" ;
  void comment() {
    const Token& t = lex_.peek();
    if (t.kind == TokenKind::kString) {
      lex_.next();  // file-level comment
    } else if (t.is_ident("BU_") || t.is_ident("EV_")) {
      const std::string what = lex_.next().text;
      expect_ident("the " + what + " name after CM_ " + what);
      expect_string("the comment string");
    } else if (t.is_ident("BO_")) {
      lex_.next();
      const std::size_t line = lex_.line();
      const std::uint32_t raw_id = expect_u32("the message ID after CM_ BO_");
      std::string text = expect_string("the comment string after CM_ BO_ <id>");
      if (Message* m = message_by_raw_id(raw_id)) {
        m->comment = std::move(text);
      } else {
        warn(line, "CM_ BO_ refers to unknown message " + std::to_string(raw_id) + "; ignored");
      }
    } else if (t.is_ident("SG_")) {
      lex_.next();
      const std::size_t line = lex_.line();
      const std::uint32_t raw_id = expect_u32("the message ID after CM_ SG_");
      const std::string name = expect_ident("the signal name after CM_ SG_ <id>");
      std::string text = expect_string("the comment string after CM_ SG_ <id> <signal>");
      if (Signal* s = signal_by(raw_id, name)) {
        s->comment = std::move(text);
      } else {
        warn(line, "CM_ SG_ refers to unknown signal " + std::to_string(raw_id) + " " + name + "; ignored");
      }
    } else {
      Token bad = lex_.next();
      fail(bad.line, "expected a comment string or BU_/BO_/SG_/EV_ after CM_, found " + bad.describe());
    }
    expect_semicolon("CM_");
  }

  Signal* signal_by(std::uint32_t raw_id, std::string_view name) {
    Message* m = message_by_raw_id(raw_id);
    if (m == nullptr) return nullptr;
    for (Signal& s : m->signals) {
      if (s.name == name) return &s;
    }
    return nullptr;
  }

  // (value "text")* up to ';'
  std::map<std::int64_t, std::string> value_pairs(std::string_view statement) {
    std::map<std::int64_t, std::string> table;
    while (!lex_.peek().is_punct(';')) {
      const std::int64_t v = expect_integer("a value or ';' in " + std::string(statement));
      table[v] = expect_string("the description string after value " + std::to_string(v));
    }
    lex_.next();
    return table;
  }

  // VAL_ id signal (value "text")* ;   or   VAL_ env_var (value "text")* ;
  void value_descriptions(const Token& kw) {
    if (lex_.peek().kind == TokenKind::kIdent) {  // environment variable: not ours
      skip_statement(kw);
      return;
    }
    const std::uint32_t raw_id = expect_u32("the message ID after VAL_");
    const std::string name = expect_ident("the signal name after VAL_ <id>");
    auto table = value_pairs("VAL_");
    if (Signal* s = signal_by(raw_id, name)) {
      s->value_table = std::move(table);
    } else {
      warn(kw.line, "VAL_ refers to unknown signal " + std::to_string(raw_id) + " " + name + "; ignored");
    }
  }

  void value_table() {
    const std::string name = expect_ident("the table name after VAL_TABLE_");
    db_.value_tables[name] = value_pairs("VAL_TABLE_");
  }

  // SIG_VALTYPE_ id signal : 1|2 ;
  void signal_value_type(const Token& kw) {
    const std::uint32_t raw_id = expect_u32("the message ID after SIG_VALTYPE_");
    const std::string name = expect_ident("the signal name after SIG_VALTYPE_ <id>");
    if (lex_.peek().is_punct(':')) lex_.next();
    const std::uint64_t type = expect_unsigned("the value type (0 integer, 1 float, 2 double)");
    expect_semicolon("SIG_VALTYPE_");
    Signal* s = signal_by(raw_id, name);
    if (s == nullptr) {
      warn(kw.line, "SIG_VALTYPE_ refers to unknown signal " + std::to_string(raw_id) + " " + name + "; ignored");
      return;
    }
    const std::uint32_t needed = type == 1 ? 32U : 64U;
    if (type == 0) {
      s->value_type = ValueType::kInteger;
    } else if (type == 1 || type == 2) {
      if (s->length != needed) {
        fail(kw.line, "signal '" + name + "' is declared " + (type == 1 ? "float" : "double") + " but has " +
                          std::to_string(s->length) + " bits; it needs " + std::to_string(needed));
      }
      s->value_type = type == 1 ? ValueType::kFloat32 : ValueType::kFloat64;
    } else {
      fail(kw.line, "SIG_VALTYPE_ type " + std::to_string(type) + " is unknown; use 0 (integer), 1 (float) or 2 (double)");
    }
  }

  static constexpr std::size_t kScratch = static_cast<std::size_t>(-1);

  Lexer lex_;
  std::string source_;
  Database db_;
  Message scratch_;
  std::optional<std::size_t> current_;  // message the next SG_ belongs to
  std::unordered_map<std::uint32_t, std::size_t> by_raw_id_;
  std::vector<std::vector<std::size_t>> signal_lines_;  // per message, per signal: SG_ line
};

}  // namespace

Database parse_dbc(std::string_view text, std::string_view source_name) {
  try {
    Parser parser(text, source_name);
    return parser.run();
  } catch (const ParseFailure& f) {
    throw InputError(Fault::kUsage, f.message, Where::at_file(std::string(source_name), f.line));
  } catch (const std::bad_alloc&) {
    // Not exit 4: a DBC is kilobytes, so a parse that runs out of memory was given something else.
    throw InputError(Fault::kUsage, "out of memory while parsing; is this really a DBC file?",
                     Where::at_file(std::string(source_name)));
  }
}

Database load_dbc_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw IoError(std::string("cannot open DBC file: ") + std::strerror(err) +
                      "; check the path (a relative [layout] dbc is taken from the config file's folder)",
                  Where::at_file(path));
  }
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw IoError("cannot read DBC file: I/O error; check the file and the disk", Where::at_file(path));
  return parse_dbc(content.str(), path);
}

}  // namespace resolver::dbc
