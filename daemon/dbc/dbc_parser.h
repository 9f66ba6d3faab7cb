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
// Failure (the one error rule, daemon/core/errors.h): a syntax error, a signal
// that does not fit its message's DLC, a bad ID or length, two messages with one ID
// throw InputError (Fault::kUsage: a DBC is configuration, exit 2) whose where()
// names the source and the line and whose message() says what was expected; a
// file that cannot be opened or read throws IoError (exit 3). References to unknown
// messages/signals in CM_/VAL_/SIG_VALTYPE_ are not fatal (warnings), as real-world
// files have them.
#pragma once

#include <string>
#include <string_view>

#include "daemon/core/errors.h"
#include "daemon/dbc/dbc_types.h"

namespace resolver::dbc {

/// Parses DBC text. `source_name` labels errors (InputError's where().file) and warnings.
[[nodiscard]] Database parse_dbc(std::string_view text, std::string_view source_name);

/// Reads and parses a file; one that cannot be opened or read is an IoError naming it.
[[nodiscard]] Database load_dbc_file(const std::string& path);

}  // namespace resolver::dbc
