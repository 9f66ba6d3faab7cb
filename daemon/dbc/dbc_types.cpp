#include "daemon/dbc/dbc_types.h"

namespace resolver::dbc {

const Signal* Message::find_signal(std::string_view signal_name) const {
  for (const Signal& s : signals) {
    if (s.name == signal_name || (!s.long_name.empty() && s.long_name == signal_name)) return &s;
  }
  return nullptr;
}

const Signal* Message::multiplexor() const {
  // A signal marked `m3M` is a second-level switch; the top-level one has no m<value>.
  for (const Signal& s : signals) {
    if (s.is_multiplexor && !s.multiplexed_by.has_value()) return &s;
  }
  return nullptr;
}

const Message* Database::find_message(std::uint32_t id, bool extended) const {
  for (const Message& m : messages) {
    if (m.id == id && m.extended == extended) return &m;
  }
  return nullptr;
}

const Message* Database::find_message(std::string_view message_name) const {
  for (const Message& m : messages) {
    if (m.name == message_name || (!m.long_name.empty() && m.long_name == message_name)) return &m;
  }
  return nullptr;
}

}  // namespace resolver::dbc
