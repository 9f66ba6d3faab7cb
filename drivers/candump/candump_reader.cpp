#include "drivers/candump/candump_reader.h"

#include <utility>

namespace resolver {

CandumpReader::Status CandumpReader::next(CanFrame& frame) {
  for (;;) {
    std::string_view line;
    const LineReader::Result got = lines_.next(line);
    if (got == LineReader::Result::kEnd) return Status::kEnd;
    if (got == LineReader::Result::kTooLong) {
      TextProblem p = lines_.too_long_problem("a candump -l log");
      problem_ = LogLineProblem{LogLineError::kLineTooLong, p.column, std::move(p.message)};
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
