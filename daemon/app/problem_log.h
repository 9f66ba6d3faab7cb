// Prints problems (rejected lines/frames) to a stream without flooding it:
// the first `per_reason` of each reason in full, then one note that further
// ones are only counted. Every one of them is still counted by the caller.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <string_view>

namespace resolver {

class ProblemLog {
 public:
  ProblemLog(std::ostream& out, std::string prefix, int per_reason = 10)
      : out_(out), prefix_(std::move(prefix)), per_reason_(per_reason) {}

  void report(std::string_view reason, const std::string& message) {
    auto it = printed_.find(reason);
    if (it == printed_.end()) it = printed_.emplace(std::string(reason), 0).first;
    const int n = ++it->second;
    if (n <= per_reason_) {
      out_ << prefix_ << message << " [" << reason << "]\n";
    } else if (n == per_reason_ + 1) {
      out_ << prefix_ << "further '" << reason << "' problems are counted (health_t, final report), not printed\n";
    }
  }

 private:
  std::ostream& out_;
  std::string prefix_;
  int per_reason_;
  std::map<std::string, int, std::less<>> printed_;
};

}  // namespace resolver
