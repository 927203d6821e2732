#include "beaconloc/dds/stop_signal.hpp"

#include <atomic>
#include <csignal>
#include <initializer_list>
#include <thread>

namespace beaconloc::dds {
namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }
}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // SIGHUP: the terminal went away; SIGPIPE: the reader of our output did (`| head`). Either
  // way stop cleanly, so that shared-memory segments are released, instead of dying.
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) sigaction(sig, &action, nullptr);
}

bool stop_requested() { return g_stop.load(); }
void request_stop() { g_stop.store(true); }

bool wait_for_stop(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!g_stop.load() && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return g_stop.load();
}

}  // namespace beaconloc::dds
