#include "daemon/app/progress_meter.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace resolver {

namespace {

/// "0.4 s", "12 s", "3 min 20 s", "1 h 05 min".
std::string duration_words(double s) {
  if (s < 10.0) return fmt::format("{:.1f} s", s);
  if (s < 60.0) return fmt::format("{:.0f} s", s);
  const auto whole = static_cast<long long>(std::lround(s));
  if (whole < 3600) return fmt::format("{} min {:02} s", whole / 60, whole % 60);
  return fmt::format("{} h {:02} min", whole / 3600, whole / 60 % 60);
}

std::string megabytes(std::uint64_t bytes) { return fmt::format("{:.1f}", static_cast<double>(bytes) / 1e6); }

}  // namespace

ProgressMeter::Options ProgressMeter::for_stderr(bool forced) {
  Options o;
  o.in_place = ::isatty(STDERR_FILENO) == 1;
  o.enabled = forced || o.in_place;
  if (forced) o.show_after = std::chrono::milliseconds(0);
  if (const char* mode = std::getenv("RESOLVER_PROGRESS")) o.enabled = std::string_view(mode) != "0";
  if (const char* ms = std::getenv("RESOLVER_PROGRESS_AFTER_MS")) {
    char* end = nullptr;
    const long v = std::strtol(ms, &end, 10);
    if (end != ms && *end == '\0' && v >= 0) o.show_after = std::chrono::milliseconds(v);  // else keep the default
  }
  return o;
}

ProgressMeter::ProgressMeter(std::FILE* out, std::string label, Options options)
    : out_(out), label_(std::move(label)), options_(options), start_(Clock::now()) {}

ProgressMeter::~ProgressMeter() { finish(); }

bool ProgressMeter::due(bool last) {
  if (!options_.enabled || finished_) return false;
  const auto now = Clock::now();
  if (now - start_ < options_.show_after) return false;
  if (!last && shown_ && now - last_draw_ < options_.every) return false;
  last_draw_ = now;
  return true;
}

void ProgressMeter::draw(const std::string& text) {
  if (options_.in_place) {
    std::fprintf(out_, "\r%s\033[K", text.c_str());  // the rest of a longer previous line erased
  } else {
    std::fprintf(out_, "%s\n", text.c_str());
  }
  std::fflush(out_);
  shown_ = true;
}

void ProgressMeter::bytes(std::uint64_t done, std::uint64_t total, std::int64_t items, bool last) {
  if (!due(last)) return;
  const double s = std::chrono::duration<double>(last_draw_ - start_).count();
  const double rate = s > 0.0 ? static_cast<double>(done) / s : 0.0;
  std::string text = label_ + ": " + megabytes(done);
  if (total > 0) {
    const double f = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
    text += fmt::format(" of {} MB ({:.0f}%)", megabytes(total), 100.0 * f);
  } else {
    text += " MB";
  }
  text += fmt::format(", {} {}, {:.1f} MB/s", items, items_word_, rate / 1e6);
  if (last) {
    text += ", done in " + duration_words(s);
  } else if (total > done && rate > 0.0) {
    text += ", ETA " + duration_words(static_cast<double>(total - done) / rate);
  }
  draw(text);
}

void ProgressMeter::fraction(double f) {
  f = std::clamp(f, 0.0, 1.0);
  if (f >= 1.0 && drew_whole_) return;  // the end is drawn once
  if (!due(f >= 1.0)) return;
  drew_whole_ = f >= 1.0;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(std::lround(f * kWidth));
  std::string text = fmt::format("{} [{}{}] {:3.0f}%", label_, std::string(static_cast<std::size_t>(filled), '#'),
                                 std::string(static_cast<std::size_t>(kWidth - filled), ' '), f * 100.0);
  const double s = std::chrono::duration<double>(last_draw_ - start_).count();
  if (f >= 1.0) {
    text += " done in " + duration_words(s);
  } else if (f > 0.01) {
    text += " ETA " + duration_words(s * (1.0 - f) / f);
  }
  draw(text);
}

void ProgressMeter::finish() {
  if (finished_) return;
  finished_ = true;
  if (shown_ && options_.in_place) {
    std::fprintf(out_, "\r\033[K");  // erased: the report that follows starts on a clean line
    std::fflush(out_);
  }
}

}  // namespace resolver
