// Full-rate sender for the vcan soak (tests/vcan/scenarios/soak.sh): the
// live-latency benchmark's paced default-bench frames written to a CAN
// interface, with CAN error frames mixed in, for a fixed time or until
// SIGTERM. Unlike canplayer and cangen it survives the link going down: a
// send that fails with ENETDOWN is counted ("sent while the link was down")
// and sending goes on, so the scenario can account for every frame:
//   attempted = frames_seen + kernel_drops + failed_down   (+ failed_other, 0 expected)
// Prints key=value lines (the vcan suite's facts) on stdout at the end.
#include <csignal>

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <iostream>
#include <thread>

#include "drivers/socketcan/socketcan_source.h"
#include "tests/bench/live_latency_feed.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*sig*/) { g_stop.store(true); }

int run(int argc, char** argv) {
  CLI::App app{"Sends default-bench frames at a fixed rate on a CAN interface (vcan soak); counts what the link "
               "refused while down. Output: sender_* key=value lines."};
  std::string iface = "vcan0";
  resolver::bench_live::PaceConfig pace;
  pace.error_every_s = 10.0;
  bool marker = true;
  app.add_option("--iface", iface, "CAN interface");
  app.add_option("--rate", pace.frames_per_s, "frames per second")->check(CLI::PositiveNumber);
  app.add_option("--burst", pace.burst, "frames back to back per wake-up")->check(CLI::PositiveNumber);
  app.add_option("--seconds", pace.seconds, "how long to send [s] (SIGTERM stops earlier)")->check(CLI::PositiveNumber);
  app.add_option("--error-every", pace.error_every_s, "one CAN error frame this often [s]; 0 = none");
  app.add_option("--marker", marker,
                 "end with one frame of ID 0x7FF after 0.5 s: the kernel reports the receive-queue drop count "
                 "(SO_RXQ_OVFL) only with a delivered frame, so this one carries the final count");
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  try {
    resolver::SocketCanOptions so;
    so.iface = iface;
    so.receive_error_frames = false;
    resolver::SocketCanSource sock = resolver::SocketCanSource::open(so);
    resolver::bench_live::FrameFeed feed(pace.frames_per_s);
    resolver::bench_live::SendCounts c = resolver::bench_live::send_paced(sock.fd(), feed, pace, g_stop);
    if (marker) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      resolver::CanFrame m;
      m.id = 0x7FF;
      m.len = 1;
      resolver::bench_live::send_one(sock.fd(), m, c);
    }
    std::cout << "sender_attempted=" << c.attempted << "\nsender_sent=" << c.sent << "\nsender_error_sent="
              << c.error_sent << "\nsender_failed_down=" << c.failed_down << "\nsender_failed_other=" << c.failed_other
              << "\nsender_late_wakeups=" << c.late_wakeups << "\nsender_max_late_us=" << static_cast<long>(c.max_late_us)
              << "\nsender_seconds=" << c.seconds << "\nsender_sample_rate_hz=" << feed.sample_rate_hz() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "live_latency_sender: " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (...) {
    std::cerr << "live_latency_sender: unexpected exception\n";
  }
  return 2;
}
