#include "drivers/candump/candump_reader.h"

#include <fmt/format.h>

namespace resolver {

CandumpReader::Status CandumpReader::next(CanFrame& frame) {
  for (;;) {
    std::string_view line;
    const LineReader::Result got = lines_.next(line);
    if (got == LineReader::Result::kEnd) return Status::kEnd;
    if (got == LineReader::Result::kTooLong) {
      problem_ = LogLineProblem{
          LogLineError::kLineTooLong, kMaxCandumpLineLength + 1,
          // No "path:line:" prefix: callers add it, as for every other problem.
          fmt::format("line is {} bytes long; at most {} are accepted - is this a candump -l log? "
                      "The line was skipped",
                      lines_.skipped_length(), kMaxCandumpLineLength)};
      return Status::kBadLine;
    }
    if (is_blank_line(line)) continue;
    if (auto problem = parse_candump_line(line, frame)) {
      problem_ = std::move(*problem);
      return Status::kBadLine;
    }
    return Status::kFrame;
  }
}

}  // namespace resolver
