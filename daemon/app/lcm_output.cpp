#include "daemon/app/lcm_output.h"

namespace resolver {

LcmOutput::LcmOutput(const std::string& url, LcmChannels channels) : lcm_(url), channels_(std::move(channels)) {
  if (!lcm_.good()) {
    throw std::runtime_error("cannot initialise LCM with URL '" + (url.empty() ? std::string("(default)") : url) +
                             "': check the URL (udpm://239.255.76.67:7667?ttl=0, file:///path?mode=w, memq://) "
                             "and, for udpm, that a multicast route exists (ip route add 224.0.0.0/4 dev lo)");
  }
}

}  // namespace resolver
