// dbc_decode FILE: the project's DBC reader and codec as a line filter, for the
// peer suite (test_dbc_peer.py) to compare against an independent reader.
//
// stdin, one frame a line:   <id hex> <s|x> <payload hex, 2 digits a byte>
// stdout, per frame:         "S\t<message>\t<signal>\t<physical %.17g>" for each signal
//                            present in the frame (multiplexing applied), then "E";
//                            "U" then "E" for an ID the DBC does not have.
// Names are the long ones (BA_ "System...LongSymbol") when the DBC has them, as
// canmatrix shows them. Exit 2 with the parser's file:line message when the DBC
// is refused; warnings go to stderr.
#include <cstdint>
#include <cstdio>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"

namespace {

const std::string& shown(const std::string& name, const std::string& long_name) {
  return long_name.empty() ? name : long_name;
}

bool parse_hex_bytes(const std::string& hex, std::vector<std::uint8_t>& out) {
  if (hex.size() % 2 != 0) return false;
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    unsigned v = 0;
    if (std::sscanf(hex.c_str() + i, "%2x", &v) != 1) return false;
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: dbc_decode FILE.dbc < frames\n";
    return 2;
  }
  resolver::dbc::Database db;
  try {
    db = resolver::dbc::load_dbc_file(argv[1]);
  } catch (const std::exception& e) {  // InputError (file:line: why) or IoError: the peer suite only needs "refused"
    std::cerr << e.what() << "\n";
    return 2;
  }
  for (const std::string& w : db.warnings) std::cerr << "warning: " << w << "\n";
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::string id_text, kind, hex;
    in >> id_text >> kind >> hex;
    std::vector<std::uint8_t> data;
    if (id_text.empty() || (kind != "s" && kind != "x") || !parse_hex_bytes(hex, data)) {
      std::cerr << "bad input line: " << line << "\n";
      return 2;
    }
    const auto id = static_cast<std::uint32_t>(std::stoul(id_text, nullptr, 16));
    const resolver::dbc::Message* m = db.find_message(id, kind == "x");
    if (m == nullptr) {
      std::cout << "U\nE\n";
      continue;
    }
    for (const resolver::dbc::Signal& s : m->signals) {
      if (!resolver::dbc::signal_present(*m, s, data)) continue;
      char value[40];
      std::snprintf(value, sizeof value, "%.17g", resolver::dbc::decode_physical(s, data));
      std::cout << "S\t" << shown(m->name, m->long_name) << "\t" << shown(s.name, s.long_name) << "\t" << value << "\n";
    }
    std::cout << "E\n";
  }
  return 0;
}
