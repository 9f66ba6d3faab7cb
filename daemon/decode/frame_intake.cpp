#include "daemon/decode/frame_intake.h"

#include <cstdio>

namespace resolver {

namespace {
/// How to read interface `name` instead: resolverd and resolver-model read one
/// interface of a log, the first with a frame of the layout.
std::string how_to_read(const std::string& name) {
  std::string asc;
  if (name.size() > 3 && name.compare(0, 3, "can") == 0 &&
      name.find_first_not_of("0123456789", 3) == std::string::npos && name.size() < 8) {
    asc = "; a Vector ASC log: the lines of channel " + std::to_string(std::stoi(name.substr(3)) + 1);
  }
  return "To read " + name + " instead, replay a log of its lines only (candump -l: grep ' " + name + " ' LOG > " +
         name + ".log" + asc + ")";
}
}  // namespace

std::string describe_frame_time(std::int64_t timestamp_us) {
  char buf[48];
  const auto sec = timestamp_us / 1000000;
  const auto usec = timestamp_us % 1000000;
  std::snprintf(buf, sizeof buf, "(%s%lld.%06lld)", timestamp_us < 0 ? "-" : "", static_cast<long long>(sec < 0 ? -sec : sec),
                static_cast<long long>(usec < 0 ? -usec : usec));
  return buf;
}

std::string describe_frame(const CanFrame& frame) {
  char id[16];
  std::snprintf(id, sizeof id, "%0*X", frame.extended ? 8 : 3, frame.id);
  return "frame " + std::string(id) + " at " + describe_frame_time(frame.timestamp_us);
}

FrameIntake::FrameIntake(std::shared_ptr<const FrameDecoder> decoder, int max_counter_delta, Callbacks callbacks)
    : decoder_(std::move(decoder)),
      max_counter_delta_(max_counter_delta),
      callbacks_(std::move(callbacks)),
      counters_(decoder_->slots().size(), CounterCheck(max_counter_delta)),
      joiner_([this](const BenchSample& s) { on_joined(s); }),
      order_joiner_([this](const BenchSample& s) { on_joined(s); }) {}

void FrameIntake::restart_sequence() {
  flush();
  joiner_.reset();
  order_joiner_.reset();
  for (auto& c : counters_) c.reset();
}

void FrameIntake::change_decoder(std::shared_ptr<const FrameDecoder> decoder, int max_counter_delta) {
  flush();
  decoder_ = std::move(decoder);
  max_counter_delta_ = max_counter_delta;
  counters_.assign(decoder_->slots().size(), CounterCheck(max_counter_delta));
  joiner_.reset();
  order_joiner_.reset();
}

void FrameIntake::count_problem(std::string_view reason, const std::string& message) {
  rejects_.add(reason);
  if (callbacks_.on_problem) callbacks_.on_problem(reason, message);
}

void FrameIntake::reject(std::string_view reason, const CanFrame& frame, std::uint64_t line, const std::string& detail) {
  rejects_.add(reason);
  if (!callbacks_.on_problem) return;
  std::string msg = line > 0 ? "line " + std::to_string(line) + ": " : std::string();
  msg += describe_frame(frame) + ": " + detail;
  callbacks_.on_problem(reason, msg);
}

std::string FrameIntake::mux_page_detail(const CanFrame& frame, std::uint64_t mux_value) const {
  const FrameDecoder::Slot* slot = decoder_->slot_for(frame);
  if (slot == nullptr || slot->mux == nullptr) return "multiplexor page not read";
  std::string pages;
  for (const FrameDecoder::RoleSignal& r : slot->roles) {
    pages += (pages.empty() ? "" : ", ") + std::string(role_name(r.role)) +
             (r.signal->multiplexed_by ? " on page " + std::to_string(*r.signal->multiplexed_by) : " on every page");
  }
  if (slot->counter != nullptr && slot->counter->multiplexed_by) {
    pages += ", counter on page " + std::to_string(*slot->counter->multiplexed_by);
  }
  return slot->message->name + " multiplexor '" + slot->mux->name + "' = " + std::to_string(mux_value) +
         " selects a page without what resolverd reads (" + pages + "); frame not used";
}

void FrameIntake::report_absent_roles(const CanFrame& frame, std::uint64_t line) {
  std::string names;
  std::int64_t n = 0;
  for (std::size_t r = 0; r < kRoleCount; ++r) {
    if ((part_.roles_absent & role_bit(static_cast<Role>(r))) == 0) continue;
    names += (names.empty() ? "" : ", ") + std::string(role_name(static_cast<Role>(r)));
    ++n;
  }
  rejects_.add("mux_role_absent", n);
  if (!callbacks_.on_problem) return;
  const std::string& message = decoder_->slots()[static_cast<std::size_t>(part_.slot)].message->name;
  callbacks_.on_problem("mux_role_absent", (line > 0 ? "line " + std::to_string(line) + ": " : std::string()) +
                                               describe_frame(frame) + ": " + message + " multiplexor page " +
                                               std::to_string(part_.mux_value) + " does not carry " + names +
                                               "; missing from this frame (not decoded from another page's bits)");
}

bool FrameIntake::from_read_interface(const CanFrame& frame, std::uint64_t line) {
  const std::string_view name = frame.iface_name();
  if (last_interface_ >= interfaces_.size() || interfaces_[last_interface_].name != name) {
    last_interface_ = 0;
    while (last_interface_ < interfaces_.size() && interfaces_[last_interface_].name != name) ++last_interface_;
    if (last_interface_ == interfaces_.size()) interfaces_.push_back(InterfaceFrames{std::string(name), 0, 0, false});
  }
  InterfaceFrames& iface = interfaces_[last_interface_];
  ++iface.frames;
  if (read_interface_ < 0 || static_cast<std::size_t>(read_interface_) == last_interface_) return true;
  rejects_.add("other_interface");
  ++iface.left_out;
  if (!callbacks_.on_problem) return false;
  const std::string& read = interfaces_[static_cast<std::size_t>(read_interface_)].name;
  std::string msg = (line > 0 ? "line " + std::to_string(line) + ": " : std::string()) + describe_frame(frame) + " on " +
                    iface.name + ": ";
  if (iface.left_out == 1) {
    msg += "the log holds frames of more than one CAN interface; only " + read +
           "'s are read (the first interface with a frame of the layout), " + iface.name +
           "'s are counted as other_interface and left out (two buses' counters cannot be joined into one sample "
           "stream). " + how_to_read(iface.name);
  } else {
    msg += "not the interface read (" + read + "): left out";
  }
  callbacks_.on_problem("other_interface", msg);
  return false;
}

std::string FrameIntake::interface_note() const {
  if (interfaces_.size() < 2) return {};
  std::string list, other;
  for (const InterfaceFrames& i : interfaces_) {
    list += (list.empty() ? "" : ", ") + i.name + " " + std::to_string(i.frames) + " frames" +
            (i.read ? " (read)" : i.left_out > 0 ? " (" + std::to_string(i.left_out) + " left out: other_interface)" : "");
    if (!i.read && other.empty()) other = i.name;
  }
  return "the log holds frames of " + std::to_string(interfaces_.size()) + " CAN interfaces: " + list +
         "; one interface's frames make one sample stream. " + how_to_read(other);
}

void FrameIntake::feed(const CanFrame& frame, std::uint64_t line) {
  ++stats_.frames_seen;
  if (!frame.iface_name().empty() && !from_read_interface(frame, line)) return;
  if (frame.error) {
    ++stats_.bus_errors;
    return;
  }
  const DecodeResult r = decoder_->decode(frame, part_, info_);
  if (r.status == DecodeStatus::kRejected) {
    std::string detail;
    switch (r.reject) {
      case FrameReject::kUnknownId: detail = "unknown CAN ID (not in the DBC's mapped messages)"; break;
      case FrameReject::kWrongDlc: detail = "length " + std::to_string(frame.len) + " differs from the DBC's DLC"; break;
      case FrameReject::kCrc: detail = "CRC-8 J1850 mismatch: frame corrupted, dropped"; break;
      case FrameReject::kRemoteFrame: detail = "remote (RTR) frame carries no data"; break;
      case FrameReject::kBenchInfoVersion: detail = "BENCH_INFO layout version is not 1"; break;
      case FrameReject::kMuxPageUnmapped: detail = mux_page_detail(frame, r.mux_value); break;
    }
    reject(to_string(r.reject), frame, line, detail);
    return;
  }
  if (read_interface_ < 0 && !frame.iface_name().empty()) {
    read_interface_ = static_cast<int>(last_interface_);
    interfaces_[last_interface_].read = true;
  }
  if (r.status == DecodeStatus::kBenchInfo) {
    ++stats_.frames_decoded;
    if (callbacks_.on_bench_info) callbacks_.on_bench_info(info_);
    return;
  }
  if (part_.roles_absent != 0) report_absent_roles(frame, line);
  if (!part_.has_counter) {
    order_joiner_.add(part_);
    ++stats_.frames_decoded;
    return;
  }
  CounterCheck& check = counters_[static_cast<std::size_t>(part_.slot)];
  const std::string& name = decoder_->slots()[static_cast<std::size_t>(part_.slot)].message->name;
  switch (check.check(part_.counter)) {
    case CounterStatus::kInitial:
    case CounterStatus::kOk: break;
    case CounterStatus::kRepeated:
      reject("counter_repeated", frame, line,
             name + " counter " + std::to_string(part_.counter) + " repeated: duplicate frame dropped");
      return;
    case CounterStatus::kSomeLost:
      stats_.frames_lost += check.lost();
      rejects_.add("counter_gap");
      rejects_.add("frames_lost", check.lost());
      if (callbacks_.on_problem) {
        callbacks_.on_problem("counter_gap", (line > 0 ? "line " + std::to_string(line) + ": " : std::string()) +
                                                 describe_frame(frame) + ": " + name + " counter jumped to " +
                                                 std::to_string(part_.counter) + ", " + std::to_string(check.lost()) +
                                                 " frame(s) lost");
      }
      break;
    case CounterStatus::kWrongSequence:
      rejects_.add("counter_wrong_sequence");
      if (callbacks_.on_problem) {
        callbacks_.on_problem("counter_wrong_sequence",
                              (line > 0 ? "line " + std::to_string(line) + ": " : std::string()) + describe_frame(frame) +
                                  ": " + name + " counter jumped to " + std::to_string(part_.counter) +
                                  " (more than " + std::to_string(max_counter_delta_) + " lost): resynchronised");
      }
      break;
  }
  if (joiner_.add(part_) == JoinResult::kDuplicate) {
    reject("duplicate_in_sample", frame, line, name + " appeared twice for counter " + std::to_string(part_.counter));
    return;
  }
  ++stats_.frames_decoded;
}

void FrameIntake::on_joined(const BenchSample& sample) {
  if (sample.complete()) {
    ++stats_.samples_complete;
  } else {
    ++stats_.samples_incomplete;
    std::string missing;
    for (std::size_t i = 0; i < decoder_->slots().size(); ++i) {
      const std::uint32_t bit = 1U << i;
      if ((sample.slots_expected & bit) != 0 && (sample.slots_present & bit) == 0) {
        missing += (missing.empty() ? "" : ", ") + decoder_->slots()[i].message->name;
      }
    }
    rejects_.add("sample_incomplete");
    if (callbacks_.on_problem) {
      callbacks_.on_problem("sample_incomplete",
                            (decoder_->has_counter() ? "sample counter " + std::to_string(sample.counter) + " (index " +
                                                           std::to_string(sample.index) + ")"
                                                     : "sample " + std::to_string(sample.index) + " at " +
                                                           describe_frame_time(sample.timestamp_us)) +
                                " is missing " + missing + "; used with what arrived");
    }
  }
  if (callbacks_.on_sample) callbacks_.on_sample(sample);
}

}  // namespace resolver
