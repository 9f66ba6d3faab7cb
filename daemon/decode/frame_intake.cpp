#include "daemon/decode/frame_intake.h"

#include <cstdio>
#include <cstdlib>

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
      joiner_([this](const BenchSample& s) { on_joined(s); },
              [this](int slot, std::int64_t frames, const BenchSample& s) { on_lost(slot, frames, s); },
              max_counter_delta),
      order_joiner_([this](const BenchSample& s) { on_joined(s); }) {}

void FrameIntake::restart_sequence() {
  flush();
  joiner_.reset();
  order_joiner_.reset();
}

void FrameIntake::change_decoder(std::shared_ptr<const FrameDecoder> decoder, int max_counter_delta) {
  flush();
  decoder_ = std::move(decoder);
  max_counter_delta_ = max_counter_delta;
  joiner_.set_window(max_counter_delta);
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
  feed_counted(frame, line);
}

void FrameIntake::feed_counted(const CanFrame& frame, std::uint64_t line) {
  const auto step = [](std::uint8_t from, std::uint8_t to) {
    return static_cast<int>(static_cast<std::int8_t>(static_cast<std::uint8_t>(to - from)));
  };
  const bool near_held = !held_.empty() && std::abs(step(held_newest_, part_.counter)) <= joiner_.window();
  // In the window: the sequence goes on (what was held were strays), unless the frame
  // repeats a slot its period has while a sequence behind is held: that sequence goes
  // on into the window (logs appended, a restart a few periods back).
  if (joiner_.in_window(part_.counter) && !(near_held && joiner_.has_slot(part_))) {
    drop_held();
    join(part_, frame, line);
    return;
  }
  if (!held_.empty()) {
    const int from_held = step(held_newest_, part_.counter);
    if (from_held > joiner_.window() || from_held < -joiner_.window()) drop_held();
  }
  if (held_.empty() || step(held_newest_, part_.counter) > 0) held_newest_ = part_.counter;
  held_.push_back(Held{part_, frame, line});
  // Ahead of the window (more periods lost than it spans): a second frame near it
  // confirms the new sequence. Behind it: frames later than the window look the
  // same, and they come between frames of the current window; a new sequence (a
  // restart, logs appended) is confirmed by kConfirmBehind frames in a row.
  constexpr std::size_t kConfirmBehind = 64;
  const bool ahead = joiner_.counter_step(held_.front().part.counter) > 0;
  if (held_.size() < (ahead ? 2 : kConfirmBehind)) return;
  std::vector<Held> sequence = std::move(held_);
  held_.clear();
  for (const Held& h : sequence) join(h.part, h.frame, h.line);
}

void FrameIntake::drop_held() {
  for (const Held& h : held_) {
    const int step = joiner_.counter_step(h.part.counter);
    const std::string& name = slot_name(h.part.slot);
    const std::string where = " counter " + std::to_string(h.part.counter) + " is " + std::to_string(step < 0 ? -step : step) +
                              " periods " + (step < 0 ? "behind" : "ahead of") + " the newest (" +
                              std::to_string(joiner_.newest_counter()) + "), more than [layout] max_counter_delta = " +
                              std::to_string(joiner_.window());
    if (step >= 0) {
      reject("counter_wrong_sequence", h.frame, h.line,
             name + where + ", and the frames after it went on from " + std::to_string(joiner_.newest_counter()) +
                 ": a stray frame, dropped");
    } else if (joiner_.note_late(h.part)) {
      reject("frames_late", h.frame, h.line,
             name + where + ": it came after its sample was used, dropped (not lost; raise max_counter_delta if the " +
                 "adapter reorders frames this far)");
    } else {
      reject("duplicate_in_sample", h.frame, h.line,
             name + where + " and its sample has it already: a repeated frame, dropped");
    }
  }
  held_.clear();
}

void FrameIntake::join(const DecodedPart& part, const CanFrame& frame, std::uint64_t line) {
  const std::string& name = slot_name(part.slot);
  const std::uint8_t newest = joiner_.newest_counter();
  const std::string counter = std::to_string(part.counter);
  switch (joiner_.add(part)) {
    case JoinResult::kAccepted: break;
    case JoinResult::kReordered:
      reject("frames_reordered", frame, line,
             name + " counter " + counter + " came after a frame of counter " + std::to_string(newest) +
                 ": reordered, joined into its own sample (not lost)");
      break;
    case JoinResult::kRepeated:
      reject("counter_repeated", frame, line, name + " counter " + counter + " repeated: duplicate frame dropped");
      return;
    case JoinResult::kDuplicate:
      reject("duplicate_in_sample", frame, line, name + " appeared twice for counter " + counter);
      return;
    case JoinResult::kLate:
      reject("frames_late", frame, line,
             name + " counter " + counter + " came after its sample was used (the newest counter is " +
                 std::to_string(newest) + "): dropped (not lost)");
      return;
    case JoinResult::kResync:
      reject("counter_wrong_sequence", frame, line,
             name + " counter jumped to " + counter + " from " + std::to_string(newest) + ": " +
                 std::to_string(joiner_.resync_step() - 1) + " periods missing as the 8-bit counter counts, more " +
                 "than [layout] max_counter_delta = " + std::to_string(max_counter_delta_) +
                 ", or a new sequence (a restart, logs appended): resynchronised, the sample index advances by " +
                 std::to_string(joiner_.resync_step()));
      break;
  }
  ++stats_.frames_decoded;
}

void FrameIntake::on_lost(int slot, std::int64_t frames, const BenchSample& sample) {
  stats_.frames_lost += frames;
  rejects_.add("counter_gap");
  rejects_.add("frames_lost", frames);
  if (!callbacks_.on_problem) return;
  const auto first = static_cast<std::uint8_t>(sample.counter - frames);
  const auto last = static_cast<std::uint8_t>(sample.counter - 1);
  callbacks_.on_problem("counter_gap", "sample counter " + std::to_string(sample.counter) + " (index " +
                                           std::to_string(sample.index) + ") at " +
                                           describe_frame_time(sample.timestamp_us) + ": " + slot_name(slot) +
                                           " counter jumped to " + std::to_string(sample.counter) + ", " +
                                           std::to_string(frames) + " frame(s) lost (" +
                                           (frames == 1 ? "counter " + std::to_string(first)
                                                        : "counters " + std::to_string(first) + ".." +
                                                              std::to_string(last)) +
                                           " missing)");
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
