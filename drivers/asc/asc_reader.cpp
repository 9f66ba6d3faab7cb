#include "drivers/asc/asc_reader.h"

namespace resolver {

AscReader::Status AscReader::next(CanFrame& frame) {
  for (;;) {
    std::string_view line;
    const LineReader::Result got = lines_.next(line);
    if (got == LineReader::Result::kEnd) return Status::kEnd;
    if (got == LineReader::Result::kTooLong) {
      problem_ = lines_.too_long_problem("a Vector ASC log");
      return Status::kBadLine;
    }
    const AscLineParser::Result r = parser_.parse(line, frame);
    if (r.kind == AscLineParser::Kind::kFrame) return Status::kFrame;
    if (r.kind == AscLineParser::Kind::kProblem) {
      problem_ = r.problem;
      return Status::kBadLine;
    }
  }
}

}  // namespace resolver
