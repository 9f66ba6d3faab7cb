#include "tools/echo/echo_output.h"

#include <stdexcept>

#include <fmt/format.h>

#include "drivers/text/json_string.h"
#include "tools/echo/json_writer.h"
#include "tools/echo/lcm_eventlog_reader.h"

namespace resolver {

bool EchoFilter::channel_matches(const std::string& channel_name) const {
  return !channel || std::regex_match(channel_name, *channel);
}

bool EchoFilter::type_matches(const LcmStruct* t) const {
  if (type.empty()) return true;
  if (t == nullptr) return false;
  return t->full_name() == type || t->name == type;
}

EchoFilter make_echo_filter(const std::string& channel_regex, const std::string& type_name) {
  EchoFilter filter;
  filter.type = type_name;
  if (!channel_regex.empty()) {
    try {
      filter.channel.emplace(channel_regex, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw std::invalid_argument(fmt::format(
          "--channel '{}': not a valid regular expression ({}); e.g. use 'RESOLVER_.*'", channel_regex, e.what()));
    }
  }
  return filter;
}

std::optional<std::string> format_message_json(const LcmJsonDecoder& decoder, const EchoFilter& filter,
                                               std::string_view channel, std::int64_t receive_utime,
                                               std::span<const std::uint8_t> data) {
  const std::string channel_name(channel);
  if (!filter.channel_matches(channel_name)) return std::nullopt;
  const DecodedMessage msg = decoder.decode(data);
  if (!filter.type_matches(msg.type)) return std::nullopt;

  std::string line = "{\"channel\":";
  text::append_json_string(line, channel_name);
  line += ",\"type\":";
  if (msg.type != nullptr) {
    text::append_json_string(line, msg.type->full_name());
  } else {
    line += "null";
  }
  line += ",\"utime\":";
  if (!msg.error.empty()) {
    line += "null,\"size\":";
    append_json_number(line, static_cast<std::int64_t>(data.size()));
    line += ",\"error\":";
    text::append_json_string(line, msg.error);
  } else {
    if (msg.utime_json) {
      line += *msg.utime_json;
    } else {
      append_json_number(line, receive_utime);
    }
    if (!msg.fields_json.empty()) {
      line.push_back(',');
      line += msg.fields_json;
    }
  }
  line.push_back('}');
  return line;
}

std::int64_t echo_log_file(const std::string& path, const LcmJsonDecoder& decoder, const EchoFilter& filter,
                           std::optional<std::int64_t> limit, const JsonLineSink& sink) {
  EventLogReader reader(path);
  std::int64_t emitted = 0;
  while (!limit || emitted < *limit) {
    const std::optional<LogEvent> ev = reader.next();
    if (!ev) break;
    const auto line = format_message_json(decoder, filter, ev->channel, ev->timestamp_us, ev->data);
    if (!line) continue;
    sink(*line);
    ++emitted;
  }
  return emitted;
}

std::vector<std::string> read_log_as_json_lines(const std::string& path, const LcmTypeRegistry& registry,
                                                const EchoFilter& filter) {
  const LcmJsonDecoder decoder(registry);
  std::vector<std::string> lines;
  echo_log_file(path, decoder, filter, std::nullopt, [&lines](const std::string& l) { lines.push_back(l); });
  return lines;
}

}  // namespace resolver
