#include "daemon/decode/frame_decoder.h"

#include <bitset>
#include <cstdio>
#include <optional>
#include <span>

#include "daemon/core/angles.h"
#include "daemon/dbc/dbc_codec.h"
#include "daemon/decode/crc8_j1850.h"
#include "daemon/decode/signal_units.h"

namespace resolver {

namespace {

/// The payload bits a signal occupies, by DBC bit number (bit k of byte b = 8b + k).
using PayloadBits = std::bitset<std::size_t{8} * 64>;

PayloadBits bits_of(const dbc::Signal& sig) {
  PayloadBits bits;
  const dbc::detail::Span span = dbc::detail::linear_span(sig, std::min(sig.length, 64U));
  for (std::uint64_t lin = span.first_lin; lin <= span.last_lin && lin < bits.size(); ++lin) {
    // Intel counts LSB-first within a byte (DBC number = linear), Motorola MSB-first.
    bits.set(sig.order == dbc::ByteOrder::kBigEndian ? (lin ^ 7U) : lin);
  }
  return bits;
}

/// "16..23" or "7, 12..15": the set bits as ranges.
std::string describe_bits(const PayloadBits& bits) {
  std::string out;
  for (std::size_t b = 0; b < bits.size(); ++b) {
    if (!bits.test(b)) continue;
    std::size_t e = b;
    while (e + 1 < bits.size() && bits.test(e + 1)) ++e;
    out += (out.empty() ? "" : ", ") + (e == b ? std::to_string(b) : std::to_string(b) + ".." + std::to_string(e));
    b = e;
  }
  return out;
}

std::string describe_signal(const dbc::Signal& sig, const PayloadBits& bits) {
  return "'" + sig.name + "' (bits " + describe_bits(bits) + ")";
}

/// Signals switched by a multiplexor to different values never share a frame.
bool can_share_a_frame(const dbc::Signal& a, const dbc::Signal& b) {
  return !(a.multiplexed_by && b.multiplexed_by && *a.multiplexed_by != *b.multiplexed_by);
}

}  // namespace

void FrameDecoder::check_overlaps(const Slot& slot, const std::function<void(const std::string&)>& problem) {
  // What resolverd reads from the message: its roles, the counter and the CRC.
  std::vector<const dbc::Signal*> used;
  for (const RoleSignal& r : slot.roles) used.push_back(r.signal);
  if (slot.counter != nullptr) used.push_back(slot.counter);
  if (slot.crc != nullptr) used.push_back(slot.crc);
  auto is_used = [&used](const dbc::Signal* s) { return std::find(used.begin(), used.end(), s) != used.end(); };
  const auto& signals = slot.message->signals;
  for (std::size_t i = 0; i < signals.size(); ++i) {
    const PayloadBits bi = bits_of(signals[i]);
    for (std::size_t j = i + 1; j < signals.size(); ++j) {
      if (!can_share_a_frame(signals[i], signals[j])) continue;
      const PayloadBits bj = bits_of(signals[j]);
      const PayloadBits both = bi & bj;
      if (both.none()) continue;
      const std::string text = "message '" + slot.message->name + "': signals " + describe_signal(signals[i], bi) +
                               " and " + describe_signal(signals[j], bj) + " overlap in bits " + describe_bits(both);
      if (is_used(&signals[i]) || is_used(&signals[j])) {
        // Two quantities decoded from the same bits: every value of one is partly the other.
        problem(text + "; fix the DBC (start bits and lengths) before using it");
      } else {
        warnings_.push_back(text + " (neither is read by resolverd, so decoding is unaffected)");
      }
    }
  }
}

void FrameDecoder::check_multiplexing(Slot& slot, const std::function<void(const std::string&)>& problem) const {
  const dbc::Message& msg = *slot.message;
  std::vector<std::pair<std::string, const dbc::Signal*>> read;  // what reads it, the signal
  for (const RoleSignal& r : slot.roles) read.emplace_back("role '" + std::string(role_name(r.role)) + "'", r.signal);
  if (slot.counter != nullptr) read.emplace_back("the counter", slot.counter);
  if (slot.crc != nullptr) read.emplace_back("the CRC", slot.crc);
  // More than one switch: which one an m<value> refers to is not simple any more.
  std::size_t switches = 0;
  for (const dbc::Signal& s : msg.signals) switches += s.is_multiplexor ? 1U : 0U;
  for (const auto& [who, sig] : read) {
    const bool switched = sig->multiplexed_by.has_value() || sig->mul_val_line != 0;
    if (!switched) continue;
    if (switches > 1 || sig->mul_val_line != 0) {
      const std::size_t line = sig->mul_val_line != 0 ? sig->mul_val_line : msg.extended_mux_line;
      problem(db_->source + ":" + std::to_string(line) + ": message '" + msg.name +
              "' uses extended multiplexing (" + msg.extended_mux_note + "), which resolverd does not decode; " + who +
              " reads '" + sig->name + "', whose presence depends on it (use one multiplexor M with m<value> " +
              "signals for what resolverd reads, or a plain signal)");
      continue;
    }
    slot.mux = msg.multiplexor();
  }
}

std::string_view to_string(FrameReject reject) {
  switch (reject) {
    case FrameReject::kUnknownId: return "unknown_id";
    case FrameReject::kWrongDlc: return "wrong_dlc";
    case FrameReject::kCrc: return "crc";
    case FrameReject::kRemoteFrame: return "remote_frame";
    case FrameReject::kBenchInfoVersion: return "bench_info_version";
    case FrameReject::kMuxPageUnmapped: return "mux_page_unmapped";
  }
  return "unknown";
}

namespace {

bool is_angle(Role role) { return role == Role::kRdAngle || role == Role::kRefAngle; }
bool is_current(Role role) { return role == Role::kIA || role == Role::kIB || role == Role::kIC; }

/// The factor from the signal's DBC unit to the role's unit, or a problem
/// naming the signal, its unit and the accepted ones.
std::optional<double> role_unit_factor(Role role, const std::string& message, const dbc::Signal& sig,
                                       std::string& problem) {
  if (!is_angle(role) && !is_current(role)) return 1.0;  // sin/cos: any consistent unit
  const auto factor = is_angle(role) ? angle_unit_to_rad(sig.unit) : current_unit_to_amps(sig.unit);
  if (factor) return factor;
  problem = "role '" + std::string(role_name(role)) + "' (" + message + "." + sig.name + "): " +
            (sig.unit.empty() ? std::string("the DBC signal has no unit") : "unit " + quote_unit(sig.unit) + " is unknown") +
            "; an " + (is_angle(role) ? "angle" : "current") + " signal must say its unit, one of: " +
            std::string(is_angle(role) ? kAngleUnitList : kCurrentUnitList) + " (set it in the DBC's SG_ line)";
  return std::nullopt;
}

}  // namespace

FrameDecoder::FrameDecoder(std::shared_ptr<const dbc::Database> db, const SignalMap& map, const Where& map_at)
    : db_(std::move(db)), map_(map) {
  std::string problems;
  auto problem = [&problems](const std::string& text) { problems += "\n  - " + text; };

  for (std::size_t r = 0; r < kRoleCount; ++r) {
    const auto& ref = map_.roles[r];
    if (!ref) continue;
    const auto role = static_cast<Role>(r);
    const dbc::Message* msg = db_->find_message(ref->message);
    if (msg == nullptr) {
      problem("role '" + std::string(role_name(role)) + "': no message '" + ref->message + "' in the DBC");
      continue;
    }
    const dbc::Signal* sig = msg->find_signal(ref->signal);
    if (sig == nullptr) {
      problem("role '" + std::string(role_name(role)) + "': message '" + ref->message + "' has no signal '" +
              ref->signal + "'");
      continue;
    }
    auto it = slot_by_id_.find(key(msg->id, msg->extended));
    int slot_index = 0;
    if (it == slot_by_id_.end()) {
      Slot slot;
      slot.message = msg;
      slot.counter = has_counter() ? msg->find_signal(map_.counter_signal) : nullptr;
      if (has_counter() && slot.counter == nullptr) {
        problem("message '" + msg->name + "' carries role '" + std::string(role_name(role)) +
                "' but has no counter signal '" + map_.counter_signal +
                "' (set layout.counter_signal, or counter_signal = \"\" for a layout without one)");
      }
      if (!map_.crc_signal.empty() && map_.crc != CrcAlgorithm::kNone) {
        slot.crc = msg->find_signal(map_.crc_signal);
        if (slot.crc == nullptr) {
          problem("message '" + msg->name + "' has no CRC signal '" + map_.crc_signal +
                  "' (set layout.crc_signal, or layout.crc = \"none\")");
        }
      }
      slot_index = static_cast<int>(slots_.size());
      slots_.push_back(slot);
      slot_by_id_[key(msg->id, msg->extended)] = slot_index;
    } else {
      slot_index = it->second;
    }
    std::string unit_problem;
    const auto factor = role_unit_factor(role, msg->name, *sig, unit_problem);
    if (!factor) problem(unit_problem);
    slots_[static_cast<std::size_t>(slot_index)].roles.push_back(RoleSignal{role, sig, factor.value_or(1.0), is_angle(role)});
    mapped_roles_ = static_cast<std::uint16_t>(mapped_roles_ | role_bit(role));
  }
  for (Slot& slot : slots_) {
    check_overlaps(slot, problem);
    check_multiplexing(slot, problem);
  }
  if (!map_.bench_info_message.empty()) {
    bench_info_ = db_->find_message(map_.bench_info_message);
    if (bench_info_ == nullptr) {
      problem("no bench info message '" + map_.bench_info_message + "' in the DBC (set layout.bench_info_message = \"\" to run without one)");
    }
  }
  if ((mapped_roles_ & role_bit(Role::kRdAngle)) == 0 &&
      (mapped_roles_ & (role_bit(Role::kSin) | role_bit(Role::kCos))) !=
          (role_bit(Role::kSin) | role_bit(Role::kCos))) {
    problem("the signal map needs rd_angle, or both sin and cos: nothing to estimate an angle from");
  }
  if (!problems.empty()) {
    Where where = map_at;
    where.option = "[layout]";
    throw InputError(Fault::kUsage, "signal map does not fit the DBC " + db_->source + ":" + problems, where);
  }
}

DecodeResult FrameDecoder::decode(const CanFrame& frame, DecodedPart& part, BenchInfo& info) const {
  DecodeResult result;
  const std::span<const std::uint8_t> data(frame.data.data(), frame.len);
  auto reject = [&result](FrameReject why) {
    result.status = DecodeStatus::kRejected;
    result.reject = why;
    return result;
  };
  const bool is_bench_info = bench_info_ != nullptr && frame.id == bench_info_->id && frame.extended == bench_info_->extended;
  const auto it = slot_by_id_.find(key(frame.id, frame.extended));
  if (it == slot_by_id_.end() && !is_bench_info) return reject(FrameReject::kUnknownId);
  if (frame.rtr) return reject(FrameReject::kRemoteFrame);
  const dbc::Message* msg = is_bench_info ? bench_info_ : slots_[static_cast<std::size_t>(it->second)].message;
  if (frame.len != msg->dlc) return reject(FrameReject::kWrongDlc);

  const dbc::Signal* crc_signal = nullptr;
  if (map_.crc == CrcAlgorithm::kBenchJ1850 && !map_.crc_signal.empty()) {
    crc_signal = is_bench_info ? msg->find_signal(map_.crc_signal) : slots_[static_cast<std::size_t>(it->second)].crc;
  }
  // Multiplexed slots: the page this frame carries (dbc_types.h: m<value> signals exist only on their page).
  const Slot* slot = is_bench_info ? nullptr : &slots_[static_cast<std::size_t>(it->second)];
  const bool muxed = slot != nullptr && slot->mux != nullptr;
  const std::uint64_t mux_value = muxed ? dbc::extract_raw(*slot->mux, data) : 0;
  auto on_page = [&](const dbc::Signal& s) { return !s.multiplexed_by || *s.multiplexed_by == mux_value; };
  if (muxed) {
    bool any_role = false;
    for (const RoleSignal& r : slot->roles) any_role = any_role || on_page(*r.signal);
    if (!any_role || (slot->counter != nullptr && !on_page(*slot->counter))) {
      result.mux_value = mux_value;
      return reject(FrameReject::kMuxPageUnmapped);
    }
    if (crc_signal != nullptr && !on_page(*crc_signal)) crc_signal = nullptr;  // this page has no CRC
  }
  if (crc_signal != nullptr && frame.len >= 8) {
    const auto sent = static_cast<std::uint8_t>(dbc::extract_raw(*crc_signal, data));
    if (sent != bench_frame_crc(frame.data.data(), frame.id)) return reject(FrameReject::kCrc);
  }

  if (is_bench_info) {
    auto get = [&](const char* name) -> double {
      const dbc::Signal* s = msg->find_signal(name);
      return s != nullptr ? dbc::decode_physical(*s, data) : 0.0;
    };
    info.layout_version = static_cast<int>(get("layout_version"));
    if (info.layout_version != 1) return reject(FrameReject::kBenchInfoVersion);
    info.p_r = static_cast<int>(get("p_r"));
    info.p = static_cast<int>(get("p"));
    info.rd_bits = static_cast<int>(get("rd_bits"));
    info.sample_rate_hz = get("sample_rate_hz");
    result.status = DecodeStatus::kBenchInfo;
    return result;
  }

  part.slot = it->second;
  part.has_counter = slot->counter != nullptr;
  part.counter = part.has_counter ? static_cast<std::uint8_t>(dbc::extract_raw(*slot->counter, data)) : 0;
  part.roles = 0;
  part.roles_absent = 0;
  part.mux_value = mux_value;
  part.timestamp_us = frame.timestamp_us;
  for (const RoleSignal& r : slot->roles) {
    if (muxed && !on_page(*r.signal)) {
      part.roles_absent = static_cast<std::uint16_t>(part.roles_absent | role_bit(r.role));
      continue;
    }
    const double value = dbc::decode_physical(*r.signal, data) * r.to_role_unit;
    part.values[static_cast<std::size_t>(r.role)] = r.wrap ? wrap_2pi(value) : value;
    part.roles = static_cast<std::uint16_t>(part.roles | role_bit(r.role));
  }
  result.status = DecodeStatus::kPart;
  return result;
}

}  // namespace resolver

namespace resolver {

std::string FrameDecoder::describe_layout() const {
  std::string out;
  for (const Slot& slot : slots_) {
    char id[16];
    std::snprintf(id, sizeof id, slot.message->extended ? "0x%08X" : "0x%03X", slot.message->id);
    out += (out.empty() ? "" : ", ") + slot.message->name + " " + id + " (";
    for (std::size_t i = 0; i < slot.roles.size(); ++i) {
      out += (i == 0 ? "" : ", ") + std::string(role_name(slot.roles[i].role)) + " = " + slot.roles[i].signal->name;
    }
    out += ")";
  }
  out += has_counter() ? ", counter '" + map_.counter_signal + "'" : ", no counter";
  return out;
}

}  // namespace resolver
