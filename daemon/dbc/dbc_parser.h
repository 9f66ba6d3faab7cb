// DBC reader: text -> Database (dbc_types.h).
//
// Understood: VERSION, NS_ (block skipped), BS_, BU_, BO_ (bit 31 of the ID
// marks a 29-bit ID), SG_ with multiplexer indicators M / m<n> / m<n>M,
// Intel (@1) and Motorola (@0) order, +/- sign, (factor,offset) [min|max]
// "unit" receivers, CM_ (global, BU_, BO_, SG_, EV_; strings may span lines),
// VAL_, VAL_TABLE_, SIG_VALTYPE_ (IEEE float/double signals), SG_MUL_VAL_
// (recorded as extended multiplexing unless it only restates m<n>), BA_
// "SystemSignalLongSymbol" / "SystemMessageLongSymbol" (long names). BA_DEF_,
// other BA_, BA_DEF_DEF_ and the other ';'-terminated attribute/relation
// statements are parsed up to their ';' and ignored. Any other keyword is
// skipped to the end of its line and noted in Database::warnings. The last
// line may end without a newline.
//
// Failure: parse_dbc never throws; a syntax error, a signal that does not fit
// its message's DLC, a bad ID or length, two messages with one ID returns a
// DbcError naming the source, the line and what was expected. References to unknown messages/signals in
// CM_/VAL_/SIG_VALTYPE_ are not fatal (warnings), as real-world files have them.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <variant>

#include "daemon/dbc/dbc_types.h"

namespace resolver::dbc {

struct DbcError {
  std::string source;    ///< file path or the name given to parse_dbc
  std::size_t line = 0;  ///< 1-based; 0 when the error is not about a line (cannot open)
  std::string message;   ///< what went wrong and what to do

  /// "file.dbc:12: expected ':' after the message name, found '8'"
  [[nodiscard]] std::string what() const;
};

/// Parses DBC text. `source_name` only labels errors and warnings.
[[nodiscard]] std::variant<Database, DbcError> parse_dbc(std::string_view text, std::string_view source_name);

/// Reads and parses a file; an unreadable file is a DbcError with line 0.
[[nodiscard]] std::variant<Database, DbcError> load_dbc_file(const std::string& path);

}  // namespace resolver::dbc
