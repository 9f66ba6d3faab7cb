// Fuzz target: parse_dbc (daemon/dbc/dbc_parser.h), then the codec on every
// signal of an accepted database.
//
// Properties checked beyond "no crash, no sanitizer report":
//   - an error names a line (>= 1, at most one past the last line) and says why;
//   - an accepted database keeps the promises the decoder relies on: every
//     signal is 1..64 bits and lies inside its message's DLC (<= 64 bytes),
//     IEEE float signals are 32/64 bits, names and IDs can be looked up;
//   - insert_raw then extract_raw gives back the low `length` bits, and
//     decode_physical / signal_present work on a payload of exactly DLC bytes.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

namespace dbc = resolver::dbc;

std::size_t count_lines(std::string_view text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
}

void check_signal(const dbc::Message& m, const dbc::Signal& s, std::uint64_t pattern) {
  FUZZ_CHECK(s.length >= 1 && s.length <= 64, "signal length outside 1..64");
  if (s.value_type == dbc::ValueType::kFloat32) FUZZ_CHECK(s.length == 32, "float signal not 32 bits");
  if (s.value_type == dbc::ValueType::kFloat64) FUZZ_CHECK(s.length == 64, "double signal not 64 bits");
  const auto span = dbc::detail::linear_span(s, s.length);
  FUZZ_CHECK((span.last_lin >> 3U) < m.dlc, "signal runs past its message's DLC");
  FUZZ_CHECK(m.find_signal(s.name) != nullptr, "signal cannot be found by its name");

  std::vector<std::uint8_t> payload(m.dlc, 0xA5);
  const std::uint64_t raw = pattern & dbc::detail::low_mask(s.length);
  dbc::insert_raw(s, raw, payload);
  FUZZ_CHECK(dbc::extract_raw(s, payload) == raw, "extract_raw(insert_raw(raw)) != raw");
  (void)dbc::extract_signed(s, payload);
  (void)dbc::decode_physical(s, payload);
  (void)dbc::signal_present(m, s, payload);
  // Shorter payloads than the DLC (a frame with a wrong length) must read as zero bits, not overrun.
  const std::span<const std::uint8_t> shorter(payload.data(), payload.size() / 2);
  (void)dbc::decode_physical(s, shorter);
  (void)dbc::signal_present(m, s, shorter);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = resolver::fuzz::as_text(data, size);
  dbc::Database db;
  try {
    db = dbc::parse_dbc(text, "fuzz.dbc");
  } catch (const resolver::InputError& error) {
    const std::uint64_t line = error.where().line;
    FUZZ_CHECK(line >= 1 && line <= count_lines(text) + 1, "refusal's line outside the text");
    FUZZ_CHECK(!error.message().empty(), "refusal without a message");
    FUZZ_CHECK(error.where().file == "fuzz.dbc", "refusal without the source name");
    return 0;
  }
  // A pattern that differs between inputs, so insert/extract sees varied bits.
  std::uint64_t pattern = 0x9E3779B97F4A7C15ULL;
  for (std::size_t i = 0; i < size; ++i) pattern = (pattern ^ data[i]) * 0x100000001B3ULL;
  for (const auto& m : db.messages) {
    FUZZ_CHECK(m.dlc <= 64, "message DLC above 64");
    FUZZ_CHECK(m.extended ? m.id <= 0x1FFFFFFFU : m.id <= 0x7FFU, "message ID out of range for its kind");
    FUZZ_CHECK(db.find_message(m.name) != nullptr, "message cannot be found by its name");
    FUZZ_CHECK(db.find_message(m.id, m.extended) != nullptr, "message cannot be found by its ID");
    for (const auto& s : m.signals) check_signal(m, s, pattern);
  }
  return 0;
}
