#include "beaconloc/dds/stop_signal.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <initializer_list>
#include <thread>

namespace beaconloc::dds {
namespace {
std::atomic<bool> g_stop{false};
std::atomic<bool> g_got_sigint{false}, g_got_sigterm{false};

// The first signal asks for a clean stop (the loops poll the flag). The same SIGINT or SIGTERM
// again (Ctrl-C twice; a supervisor repeating its request) means the clean stop is not coming --
// a thread stuck in work the loops cannot interrupt, a teardown waiting on it -- and ends the
// process at once. A different signal does not: Ctrl-C sends SIGINT to a whole process group,
// whose parent may then SIGTERM its children once to stop them in order. SIGPIPE and SIGHUP
// never do: output to a closed pipe raises SIGPIPE on every write of the clean stop. Only
// async-signal-safe calls here.
extern "C" void on_stop_signal(int sig) {
  g_stop.store(true);
  std::atomic<bool>* seen = sig == SIGINT ? &g_got_sigint : sig == SIGTERM ? &g_got_sigterm : nullptr;
  if (!seen || !seen->exchange(true)) return;
  static const char kMessage[] = "beaconloc: second stop signal: exiting without a clean stop\n";
  const ssize_t ignored = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  (void)ignored;
  ::_exit(128 + sig);
}
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
