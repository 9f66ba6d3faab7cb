// Parser behaviour on small hand-written DBC texts: what is read, and that each
// malformed input is rejected with the right line and a message naming what
// was expected.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"

namespace resolver::dbc {
namespace {

Database parse_ok(const std::string& text) {
  try {
    return parse_dbc(text, "test.dbc");
  } catch (const InputError& e) {
    ADD_FAILURE() << "unexpected error: " << e.what();
    return {};
  }
}

/// What an InputError from the parser says, copied out for the checks below.
struct Refusal {
  std::size_t line = 0;
  std::string message;
  std::string text;  ///< what()
  Fault fault = Fault::kData;
  [[nodiscard]] const std::string& what() const { return text; }
};

Refusal refusal_of(const InputError& e) {
  return Refusal{static_cast<std::size_t>(e.where().line), e.message(), e.what(), e.fault()};
}

Refusal parse_bad(const std::string& text) {
  try {
    (void)parse_dbc(text, "bad.dbc");
  } catch (const InputError& e) {
    const Refusal r = refusal_of(e);
    EXPECT_EQ(e.where().file, "bad.dbc") << e.what();
    EXPECT_EQ(r.fault, Fault::kUsage) << "a DBC is configuration: exit 2";
    return r;
  }
  ADD_FAILURE() << "expected an error for:\n" << text;
  return {};
}

// Line 1 comment; the message starts on line 3, its first signal on line 4.
const std::string kHeader = "VERSION \"1.2\"\n\nBO_ 291 TEST: 8 ECU\n";

TEST(DbcParser, ReadsHeaderMessageAndSignalFields) {
  const Database db = parse_ok(
      "VERSION \"1.2\"\n"
      "NS_ :\n\tCM_\n\tBA_DEF_\n\tVAL_\n\n"
      "BS_:\n"
      "BU_: ECU Logger Dash\n"
      "BO_ 291 TEST: 8 ECU\n"
      " SG_ speed : 7|16@0- (0.125,-40) [-4136|4055.875] \"km/h\" Logger,Dash\n"
      " SG_ flag : 16|1@1+ (1,0) [0|1] \"\" Vector__XXX\n");
  EXPECT_EQ(db.version, "1.2");
  EXPECT_EQ(db.nodes, (std::vector<std::string>{"ECU", "Logger", "Dash"}));
  ASSERT_EQ(db.messages.size(), 1U);
  const Message& m = db.messages[0];
  EXPECT_EQ(m.id, 291U);
  EXPECT_FALSE(m.extended);
  EXPECT_EQ(m.name, "TEST");
  EXPECT_EQ(m.dlc, 8U);
  EXPECT_EQ(m.sender, "ECU");
  ASSERT_EQ(m.signals.size(), 2U);
  const Signal& s = m.signals[0];
  EXPECT_EQ(s.name, "speed");
  EXPECT_EQ(s.start_bit, 7U);
  EXPECT_EQ(s.length, 16U);
  EXPECT_EQ(s.order, ByteOrder::kBigEndian);
  EXPECT_TRUE(s.is_signed);
  EXPECT_EQ(s.factor, 0.125);
  EXPECT_EQ(s.offset, -40.0);
  EXPECT_EQ(s.minimum, -4136.0);
  EXPECT_EQ(s.maximum, 4055.875);
  EXPECT_EQ(s.unit, "km/h");
  EXPECT_EQ(s.receivers, (std::vector<std::string>{"Logger", "Dash"}));
  EXPECT_EQ(m.signals[1].order, ByteOrder::kLittleEndian);
  EXPECT_FALSE(m.signals[1].is_signed);
  EXPECT_TRUE(m.signals[1].receivers.empty()) << "Vector__XXX means no receiver";
  EXPECT_EQ(db.find_message("TEST"), &m);
  EXPECT_EQ(db.find_message(291, false), &m);
  EXPECT_EQ(db.find_message(291, true), nullptr);
  EXPECT_EQ(m.find_signal("flag"), &m.signals[1]);
  EXPECT_EQ(m.find_signal("nope"), nullptr);
}

TEST(DbcParser, ExtendedIdIsBit31) {
  const std::uint32_t id29 = 0x18FEF100U;  // a J1939 PGN-style 29-bit ID
  const Database db = parse_ok("BO_ " + std::to_string(0x80000000U | id29) + " EEC1: 8 Engine\n");
  ASSERT_EQ(db.messages.size(), 1U);
  EXPECT_EQ(db.messages[0].id, id29);
  EXPECT_TRUE(db.messages[0].extended);
  EXPECT_NE(db.find_message(id29, true), nullptr);
  EXPECT_EQ(db.find_message(id29, false), nullptr);
}

TEST(DbcParser, CommentsIncludingMultiLineAndEscapedQuotes) {
  const Database db = parse_ok(kHeader +
                               " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                               "CM_ \"file comment\";\n"
                               "CM_ BU_ ECU \"the ECU\";\n"
                               "CM_ BO_ 291 \"first line\nsecond \\\"quoted\\\" line\";\n"
                               "CM_ SG_ 291 a \"signal a\";\n"
                               "CM_ SG_ 999 a \"dangling\";\n");
  const Message& m = db.messages.at(0);
  EXPECT_EQ(m.comment, "first line\nsecond \"quoted\" line");
  EXPECT_EQ(m.signals.at(0).comment, "signal a");
  ASSERT_EQ(db.warnings.size(), 1U);
  // Lines: 1-3 header, 4 SG_, 5-6 CM_, 7-8 the two-line CM_ BO_, 9 CM_ SG_, 10 the dangling one.
  EXPECT_NE(db.warnings[0].find("test.dbc:10:"), std::string::npos) << db.warnings[0];
}

TEST(DbcParser, ValueTablesAndAttributes) {
  const Database db = parse_ok(kHeader +
                               " SG_ gear : 0|4@1+ (1,0) [0|15] \"\" ECU\n"
                               "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 10000;\n"
                               "BA_DEF_DEF_ \"GenMsgCycleTime\" 100;\n"
                               "BA_ \"GenMsgCycleTime\" BO_ 291 20;\n"
                               "VAL_TABLE_ Gears 0 \"P\" 1 \"R\" 2 \"N\" 3 \"D\" ;\n"
                               "VAL_ 291 gear 0 \"Park\" 1 \"Reverse\" -1 \"invalid\" ;\n");
  const Signal& s = db.messages.at(0).signals.at(0);
  ASSERT_EQ(s.value_table.size(), 3U);
  EXPECT_EQ(s.value_table.at(0), "Park");
  EXPECT_EQ(s.value_table.at(1), "Reverse");
  EXPECT_EQ(s.value_table.at(-1), "invalid");
  ASSERT_EQ(db.value_tables.count("Gears"), 1U);
  EXPECT_EQ(db.value_tables.at("Gears").at(3), "D");
  EXPECT_TRUE(db.warnings.empty());
}

TEST(DbcParser, UnknownKeywordIsSkippedLineWiseWithAWarning) {
  // Line 5 holds an unknown keyword with junk and a string that runs on to line 6;
  // parsing resumes on line 7.
  const Database db = parse_ok(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                                         "FOO_BAR_ 1 2 ### \"multi\nline\"\n"
                                         "BO_ 292 B: 8 ECU\n");
  ASSERT_EQ(db.messages.size(), 2U);
  EXPECT_EQ(db.messages[1].name, "B");
  ASSERT_EQ(db.warnings.size(), 1U);
  EXPECT_NE(db.warnings[0].find("test.dbc:5:"), std::string::npos) << db.warnings[0];
  EXPECT_NE(db.warnings[0].find("FOO_BAR_"), std::string::npos) << db.warnings[0];
}

TEST(DbcParser, SignalAfterAnotherStatementIsNotAttachedToTheEarlierMessage) {
  const Refusal e = parse_bad(kHeader + "CM_ BO_ 291 \"x\";\n SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n");
  EXPECT_EQ(e.line, 5U) << e.what();
  EXPECT_NE(e.message.find("not inside a message"), std::string::npos) << e.what();
}

TEST(DbcParser, MultiplexedSignalsDecodeOnlyForTheirMuxValue) {
  const Database db = parse_ok(kHeader +
                               " SG_ mode M : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                               " SG_ temp m1 : 8|16@1- (0.1,0) [0|0] \"degC\" ECU\n"
                               " SG_ volts m2 : 8|16@1+ (0.01,0) [0|0] \"V\" ECU\n"
                               " SG_ always : 24|8@1+ (1,0) [0|0] \"\" ECU\n");
  const Message& m = db.messages.at(0);
  ASSERT_EQ(m.multiplexor(), m.find_signal("mode"));
  const Signal& temp = *m.find_signal("temp");
  const Signal& volts = *m.find_signal("volts");
  const Signal& always = *m.find_signal("always");
  EXPECT_EQ(temp.multiplexed_by, 1U);
  EXPECT_EQ(volts.multiplexed_by, 2U);
  for (std::uint64_t mode = 0; mode < 4; ++mode) {
    std::array<std::uint8_t, 8> d{};
    insert_raw(*m.multiplexor(), mode, d);
    EXPECT_EQ(signal_present(m, temp, d), mode == 1) << "mode " << mode;
    EXPECT_EQ(signal_present(m, volts, d), mode == 2) << "mode " << mode;
    EXPECT_TRUE(signal_present(m, always, d));
    EXPECT_TRUE(signal_present(m, *m.multiplexor(), d));
  }
}

TEST(DbcParser, DuplicateMessageIdIsAnErrorNamingBothMessagesAndLines) {
  const Refusal e = parse_bad(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                                         "BO_ 292 OTHER: 8 ECU\n"
                                         "BO_ 291 AGAIN: 8 ECU\n");
  EXPECT_EQ(e.line, 6U) << e.what();
  EXPECT_NE(e.message.find("message 'AGAIN' has ID 0x123, already used by message 'TEST' at bad.dbc:3"),
            std::string::npos)
      << e.what();
  // The same number as a standard and as an extended ID are two messages.
  const Database db = parse_ok(kHeader + "BO_ " + std::to_string(0x80000000U | 291U) + " EXT: 8 ECU\n");
  EXPECT_EQ(db.messages.size(), 2U);
  EXPECT_EQ(db.messages.at(0).line, 3U);
}

TEST(DbcParser, ExtendedMultiplexingIsRecordedWithItsLine) {
  // Lines 4..7: the top switch, a second-level switch m1M, and signals of each.
  const Database nested = parse_ok(kHeader +
                                   " SG_ mode M : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                                   " SG_ sub m1M : 8|8@1+ (1,0) [0|0] \"\" ECU\n"
                                   " SG_ x m2 : 16|8@1+ (1,0) [0|0] \"\" ECU\n"
                                   " SG_ y m0 : 8|8@1+ (1,0) [0|0] \"\" ECU\n");
  const Message& m = nested.messages.at(0);
  EXPECT_EQ(m.extended_mux_line, 5U);
  EXPECT_NE(m.extended_mux_note.find("'sub' is a second-level multiplexor (m1M)"), std::string::npos)
      << m.extended_mux_note;
  EXPECT_EQ(m.find_signal("x")->line, 6U);

  // SG_MUL_VAL_ with a range is extended; a single n-n range of the top switch only restates m<n>.
  const std::string simple = kHeader +
                             " SG_ mode M : 0|8@1+ (1,0) [0|0] \"\" ECU\n"
                             " SG_ a m1 : 8|8@1+ (1,0) [0|0] \"\" ECU\n"
                             " SG_ b m2 : 8|8@1+ (1,0) [0|0] \"\" ECU\n";
  const Database restated = parse_ok(simple + "SG_MUL_VAL_ 291 a mode 1-1;\n");
  EXPECT_EQ(restated.messages.at(0).extended_mux_line, 0U);
  EXPECT_EQ(restated.messages.at(0).find_signal("a")->mul_val_line, 0U);
  const Database ranged = parse_ok(simple + "SG_MUL_VAL_ 291 a mode 1-1, 3-5;\n");
  EXPECT_EQ(ranged.messages.at(0).extended_mux_line, 7U);
  EXPECT_EQ(ranged.messages.at(0).find_signal("a")->mul_val_line, 7U);
  EXPECT_EQ(ranged.messages.at(0).find_signal("b")->mul_val_line, 0U);
  EXPECT_NE(ranged.messages.at(0).extended_mux_note.find("'a' present for switch 'mode' in 1-1,3-5"),
            std::string::npos)
      << ranged.messages.at(0).extended_mux_note;
}

TEST(DbcParser, LastSignalLineWithoutNewlineParses) {
  for (const std::string receivers : {" ECU", " ECU,GW", "", " Vector__XXX"}) {
    const Database db = parse_ok(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\"" + receivers);
    ASSERT_EQ(db.messages.size(), 1U) << receivers;
    ASSERT_EQ(db.messages[0].signals.size(), 1U) << receivers;
    EXPECT_EQ(db.messages[0].signals[0].name, "a");
  }
  const Database db = parse_ok(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU,GW");
  EXPECT_EQ(db.messages[0].signals[0].receivers, (std::vector<std::string>{"ECU", "GW"}));
}

TEST(DbcParser, LongNamesFromAttributesAreFoundBesideTheShortOnes) {
  // As CANdb++ and cantools write names over 32 characters: a short name on the
  // BO_/SG_ line, the full one in a BA_ (the attribute definitions come first).
  const std::string long_signal = "ResolverSineEnvelopeDemodulatedCounts";     // 37 characters
  const std::string long_message = "ResolverFeedbackSampleOfOneControlPeriod";  // 40 characters
  const Database db = parse_ok(
      "VERSION \"\"\n\nBO_ 291 ResolverFeedbackSampleOfOneCont: 8 ECU\n"
      " SG_ ResolverSineEnvelopeDemodul_0000 : 0|16@1- (1,0) [0|0] \"\" ECU\n"
      " SG_ other : 16|8@1+ (1,0) [0|0] \"\" ECU\n"
      "BA_DEF_ SG_ \"SystemSignalLongSymbol\" STRING ;\n"
      "BA_DEF_ BO_ \"SystemMessageLongSymbol\" STRING ;\n"
      "BA_DEF_DEF_ \"SystemSignalLongSymbol\" \"\";\n"
      "BA_ \"SystemMessageLongSymbol\" BO_ 291 \"" + long_message + "\";\n"
      "BA_ \"SystemSignalLongSymbol\" SG_ 291 ResolverSineEnvelopeDemodul_0000 \"" + long_signal + "\";\n"
      "BA_ \"GenSigStartValue\" SG_ 291 other 3;\n"
      "VAL_ 291 ResolverSineEnvelopeDemodul_0000 0 \"zero\" ;\n");
  EXPECT_TRUE(db.warnings.empty()) << db.warnings.front();
  const Message* m = db.find_message(long_message);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m, db.find_message("ResolverFeedbackSampleOfOneCont"));
  const Signal* s = m->find_signal(long_signal);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s, m->find_signal("ResolverSineEnvelopeDemodul_0000"));
  EXPECT_EQ(s->value_table.at(0), "zero");  // VAL_ after the BA_ still names the short one
  EXPECT_EQ(m->find_signal("other")->long_name, "");
  // A long name for a signal that does not exist is a warning with its line.
  const Database dangling = parse_ok(kHeader + "BA_ \"SystemSignalLongSymbol\" SG_ 291 nope \"x\";\n");
  ASSERT_EQ(dangling.warnings.size(), 1U);
  EXPECT_NE(dangling.warnings[0].find("test.dbc:4: BA_ \"SystemSignalLongSymbol\" refers to unknown signal 291 nope"),
            std::string::npos)
      << dangling.warnings[0];
}

TEST(DbcParser, MultiplexedSignalWithoutMultiplexorIsAnError) {
  const Refusal e = parse_bad(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n SG_ b m3 : 8|8@1+ (1,0) [0|0] \"\" ECU\n");
  EXPECT_EQ(e.line, 5U) << e.what();
  EXPECT_NE(e.message.find("no multiplexor"), std::string::npos) << e.what();
}

TEST(DbcParser, FloatSignalsFromSigValtype) {
  const Database db = parse_ok(kHeader + " SG_ f : 0|32@1- (1,0) [0|0] \"\" ECU\nSIG_VALTYPE_ 291 f : 1;\n");
  EXPECT_EQ(db.messages.at(0).signals.at(0).value_type, ValueType::kFloat32);
  const Refusal e = parse_bad(kHeader + " SG_ f : 0|16@1- (1,0) [0|0] \"\" ECU\nSIG_VALTYPE_ 291 f : 2;\n");
  EXPECT_EQ(e.line, 5U) << e.what();
  EXPECT_NE(e.message.find("needs 64"), std::string::npos) << e.what();
}

struct BadCase {
  const char* name;
  std::string text;
  std::size_t line;
  const char* expected_words;  // must appear in the message
};

TEST(DbcParser, SyntaxErrorsNameTheLineAndWhatWasExpected) {
  const BadCase cases[] = {
      {"missing colon after message name", kHeader + "BO_ 292 OTHER 8 ECU\n", 4, "expected ':' after the message name"},
      {"non-numeric id", "\n\nBO_ abc X: 8 ECU\n", 3, "expected the message ID"},
      {"fractional start bit", kHeader + " SG_ a : 1.5|8@1+ (1,0) [0|0] \"\" ECU\n", 4, "start bit"},
      {"missing pipe", kHeader + " SG_ a : 0 8@1+ (1,0) [0|0] \"\" ECU\n", 4, "expected '|' between start bit and length"},
      {"bad byte order", kHeader + " SG_ a : 0|8@2+ (1,0) [0|0] \"\" ECU\n", 4, "byte order 1 (Intel) or 0 (Motorola)"},
      {"missing sign", kHeader + " SG_ a : 0|8@1 (1,0) [0|0] \"\" ECU\n", 4, "'+' (unsigned) or '-' (signed)"},
      {"missing comma in scale", kHeader + " SG_ a : 0|8@1+ (1 0) [0|0] \"\" ECU\n", 4, "expected ',' between factor and offset"},
      {"missing bracket", kHeader + " SG_ a : 0|8@1+ (1,0) 0|0] \"\" ECU\n", 4, "expected '[' before the minimum"},
      {"unit not a string", kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] V ECU\n", 4, "expected the unit string"},
      {"bad mux indicator", kHeader + " SG_ a x7 : 0|8@1+ (1,0) [0|0] \"\" ECU\n", 4, "multiplexer indicator"},
      {"signal outside a message", "VERSION \"\"\n SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n", 2, "not inside a message"},
      {"signal past the DLC", kHeader + " SG_ a : 60|8@1+ (1,0) [0|0] \"\" ECU\n", 4, "has DLC 8"},
      {"motorola signal past the DLC", kHeader + " SG_ a : 63|16@0+ (1,0) [0|0] \"\" ECU\n", 4, "needs bytes 7..8"},
      {"zero length", kHeader + " SG_ a : 0|0@1+ (1,0) [0|0] \"\" ECU\n", 4, "1..64 bits"},
      {"too long", kHeader + " SG_ a : 0|65@1+ (1,0) [0|0] \"\" ECU\n", 4, "1..64 bits"},
      {"standard id too large", "\nBO_ 2048 X: 8 ECU\n", 2, "11-bit"},
      {"dlc too large", "\nBO_ 1 X: 65 ECU\n", 2, "at most 64 bytes"},
      {"CM_ missing semicolon", kHeader + "CM_ BO_ 291 \"text\"\nBO_ 5 Y: 8 ECU\n", 5, "expected ';' to end the CM_"},
      {"unterminated string", kHeader + "CM_ BO_ 291 \"text;\n\n", 4, "unterminated string"},
      {"VAL_ value not a number", kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\nVAL_ 291 a x \"y\" ;\n", 5, "expected a value or ';'"},
      {"BA_ without semicolon", kHeader + "BA_ \"x\" BO_ 291 20\n", 4, "no terminating ';'"},
      {"garbage at statement start", kHeader + "\n$\n", 5, "expected a keyword"},
      {"duplicate signal", kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" ECU\n SG_ a : 8|8@1+ (1,0) [0|0] \"\" ECU\n", 5, "defined twice"},
  };
  for (const BadCase& c : cases) {
    const Refusal e = parse_bad(c.text);
    EXPECT_EQ(e.line, c.line) << c.name << ": " << e.what();
    EXPECT_NE(e.message.find(c.expected_words), std::string::npos) << c.name << ": " << e.what();
    EXPECT_EQ(e.what().rfind("bad.dbc:" + std::to_string(c.line) + ": ", 0), 0U) << c.name << ": " << e.what();
  }
}

TEST(DbcParser, MissingFileIsAnErrorNotACrash) {
  try {
    (void)load_dbc_file("/nonexistent/dir/none.dbc");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {  // a std::system_error: exit 3, like every file that cannot be read
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/none.dbc: cannot open DBC file: ", 0), 0U) << e.what();
  }
}

TEST(DbcParser, EmptyAndWhitespaceInputsGiveEmptyDatabases) {
  EXPECT_TRUE(parse_ok("").messages.empty());
  EXPECT_TRUE(parse_ok("\xEF\xBB\xBF\r\n  \t\r\n").messages.empty());
}

TEST(DbcParser, IndependentSignalPseudoMessageIsDropped) {
  const Database db = parse_ok("BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n"
                               " SG_ orphan : 0|8@1+ (1,0) [0|0] \"\" Vector__XXX\n"
                               "BO_ 1 REAL: 8 ECU\n");
  ASSERT_EQ(db.messages.size(), 1U);
  EXPECT_EQ(db.messages[0].name, "REAL");
}

}  // namespace
}  // namespace resolver::dbc

namespace resolver::dbc {
namespace {

// Robustness: every truncation of a real file, and random byte damage to it,
// parses to a Database or to an error whose line exists in the input.
TEST(DbcParserRobustness, TruncatedAndDamagedFilesNeverCrash) {
  std::ifstream in(RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc");
  ASSERT_TRUE(in) << "cannot open proto/resolver_bench.dbc";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string full = ss.str();
  const auto check = [](const std::string& text, const std::string& what) {
    try {
      (void)parse_dbc(text, "damaged.dbc");
    } catch (const InputError& e) {
      const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1U;
      EXPECT_GE(e.where().line, 1U) << what << ": " << e.what();
      EXPECT_LE(e.where().line, lines) << what << ": " << e.what();
      EXPECT_FALSE(e.message().empty()) << what;
    }
  };
  for (std::size_t n = 0; n <= full.size(); n += 7) check(full.substr(0, n), "prefix " + std::to_string(n));
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    std::string text = full;
    for (int k = 0; k < 3; ++k) text[rng() % text.size()] = static_cast<char>(rng());
    check(text, "damage " + std::to_string(i));
  }
}

}  // namespace
}  // namespace resolver::dbc
