#include "daemon/app/lcm_output.h"

#include "daemon/core/errors.h"

namespace resolver {

LcmOutput::LcmOutput(const std::string& url, LcmChannels channels) : channels_(std::move(channels)) {
  if (const auto file = LcmLogWriter::parse_url(url)) {
    writer_ = std::make_unique<LcmLogWriter>(*file);  // throws "cannot open <path> for the LCM log: ..."
    return;
  }
  lcm_ = std::make_unique<lcm::LCM>(url);
  if (!lcm_->good()) {
    throw IoError("cannot initialise LCM with URL '" + (url.empty() ? std::string("(default)") : url) +
                             "': check the URL (udpm://239.255.76.67:7667?ttl=0, file:///path?mode=w, memq://) "
                             "and, for udpm, that a multicast route exists (ip route add 224.0.0.0/4 dev lo)");
  }
}

bool LcmOutput::flush() { return writer_ ? writer_->flush() : true; }

}  // namespace resolver
