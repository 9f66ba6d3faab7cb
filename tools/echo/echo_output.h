// One LCM message -> one JSON line, and a whole event log -> JSON lines.
//
// A decoded message prints as
//   {"channel":"RESOLVER_ANGLE","type":"resolver.angle_t","utime":123,...members...}
// where "utime" is the message's own utime member, or the receive/log time [us]
// when its type has none. A message that cannot be decoded is not dropped:
//   {"channel":"X","type":null,"utime":null,"size":12,"error":"unknown fingerprint 0x..."}
// ("type" names the type when the fingerprint matched but the bytes did not).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <regex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tools/echo/lcm_json_decoder.h"

namespace resolver {

struct EchoFilter {
  /// Must match the whole channel name (like LCM's own subscriptions); empty = all.
  std::optional<std::regex> channel;
  /// Full ("resolver.angle_t") or short ("angle_t") type name; empty = all types,
  /// including undecodable messages. When set, undecodable unknown types are skipped.
  std::string type;

  bool channel_matches(const std::string& channel_name) const;
  bool type_matches(const LcmStruct* type) const;
};

/// Builds an EchoFilter from the command-line text. Throws std::invalid_argument
/// naming --channel when `channel_regex` is not a valid ECMAScript regex.
EchoFilter make_echo_filter(const std::string& channel_regex, const std::string& type_name);

/// The JSON line (no trailing newline) for one message, or nullopt when the
/// filter rejects it. Never throws for bad message bytes.
std::optional<std::string> format_message_json(const LcmJsonDecoder& decoder, const EchoFilter& filter,
                                               std::string_view channel, std::int64_t receive_utime,
                                               std::span<const std::uint8_t> data);

using JsonLineSink = std::function<void(const std::string& line)>;

/// Streams every accepted message of the log at `path` to `sink`, stopping
/// after `limit` lines when given. Returns the number of lines emitted.
/// Throws EventLogError (file, byte offset) on a malformed log, after the
/// lines of all the good events before the problem have been emitted.
std::int64_t echo_log_file(const std::string& path, const LcmJsonDecoder& decoder, const EchoFilter& filter,
                           std::optional<std::int64_t> limit, const JsonLineSink& sink);

/// Convenience for tests and tools: the whole log as JSON lines.
/// Throws EventLogError like echo_log_file.
std::vector<std::string> read_log_as_json_lines(const std::string& path, const LcmTypeRegistry& registry,
                                                const EchoFilter& filter = {});

}  // namespace resolver
