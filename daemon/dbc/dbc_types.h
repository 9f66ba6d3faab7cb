// The in-memory form of a CAN database (.dbc): messages, their signals, and
// the value tables and comments attached to them.
//
// A Database is built once by parse_dbc() (dbc_parser.h) and then only read;
// decoders keep `const Message*` / `const Signal*` into it, so do not modify
// its vectors after handing out pointers. Decoding a payload with a Signal is
// in dbc_codec.h.
//
// Bit numbering is the DBC one: bit k (0 = LSB) of payload byte b is bit
// 8*b + k. An Intel (@1) signal's start_bit is its least significant bit and it
// grows towards higher bit numbers; a Motorola (@0) signal's start_bit is its
// most significant bit and it grows towards less significant bits of the same
// byte, then continues at bit 7 of the next byte (the "sawtooth").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace resolver::dbc {

enum class ByteOrder : std::uint8_t {
  kLittleEndian,  ///< Intel, `@1` in a DBC
  kBigEndian,     ///< Motorola, `@0` in a DBC
};

/// How the raw bits are interpreted (SIG_VALTYPE_).
enum class ValueType : std::uint8_t {
  kInteger,  ///< two's complement or unsigned per Signal::is_signed (the default)
  kFloat32,  ///< IEEE 754 single (SIG_VALTYPE_ ... : 1), length must be 32
  kFloat64,  ///< IEEE 754 double (SIG_VALTYPE_ ... : 2), length must be 64
};

struct Signal {
  std::string name;       ///< as on the SG_ line (at most 32 characters in files of Vector's tools)
  /// The full name when it is longer (BA_ "SystemSignalLongSymbol", written by CANdb++ and
  /// cantools); "" when none. find_signal() answers to either.
  std::string long_name;
  std::uint32_t start_bit = 0;  ///< DBC numbering (see file comment)
  std::uint32_t length = 0;     ///< [bits] 1..64
  ByteOrder order = ByteOrder::kLittleEndian;
  bool is_signed = false;
  double factor = 1.0, offset = 0.0, minimum = 0.0, maximum = 0.0;  ///< physical = raw * factor + offset
  std::string unit;
  std::vector<std::string> receivers;  ///< node names; the DBC placeholder Vector__XXX is dropped
  bool is_multiplexor = false;                 ///< `M`
  std::optional<std::uint64_t> multiplexed_by;  ///< `m<value>`: present only when the multiplexor has this value
  std::map<std::int64_t, std::string> value_table;  ///< from VAL_ for this signal
  std::string comment;                              ///< from CM_ SG_
  ValueType value_type = ValueType::kInteger;        ///< from SIG_VALTYPE_
  std::size_t line = 0;          ///< its SG_ line in the source (0 for a Signal built in code)
  std::size_t mul_val_line = 0;  ///< an SG_MUL_VAL_ line that gives it value ranges of a switch (0: none)
};

struct Message {
  std::uint32_t id = 0;   ///< arbitration ID without the DBC's extended flag (bit 31)
  bool extended = false;  ///< 29-bit ID
  std::string name;       ///< as on the BO_ line
  std::string long_name;  ///< BA_ "SystemMessageLongSymbol"; "" when none. find_message() answers to either.
  std::uint32_t dlc = 0;  ///< [bytes] payload length declared in the DBC (0..64)
  std::string sender;
  std::vector<Signal> signals;
  std::string comment;  ///< from CM_ BO_
  std::size_t line = 0;  ///< its BO_ line in the source (0 for a Message built in code)
  /// Extended multiplexing (a second-level switch `m<n>M`, a second `M`, or
  /// SG_MUL_VAL_ ranges): the first line that uses it and what it is, for
  /// errors; 0 when the message multiplexes simply (one `M`, `m<value>` signals) or not at all.
  std::size_t extended_mux_line = 0;
  std::string extended_mux_note;

  /// nullptr when the message has no signal of that name (or long name).
  [[nodiscard]] const Signal* find_signal(std::string_view signal_name) const;
  /// The top-level multiplexor switch (`M`), nullptr when the message is not multiplexed.
  [[nodiscard]] const Signal* multiplexor() const;
};

struct Database {
  std::string source;                 ///< the file (or name given to parse_dbc): errors say source:line
  std::vector<Message> messages;
  std::string version;                ///< VERSION "..."
  std::vector<std::string> nodes;     ///< BU_
  std::map<std::string, std::map<std::int64_t, std::string>, std::less<>> value_tables;  ///< VAL_TABLE_
  /// Non-fatal findings while parsing ("file.dbc:40: CM_ refers to unknown message 0x123; ignored").
  std::vector<std::string> warnings;

  /// nullptr when no message has that ID (`id` without flag bits).
  [[nodiscard]] const Message* find_message(std::uint32_t id, bool extended) const;
  /// nullptr when no message has that name (or long name).
  [[nodiscard]] const Message* find_message(std::string_view message_name) const;
};

}  // namespace resolver::dbc
