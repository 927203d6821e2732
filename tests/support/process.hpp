#pragma once
// Child processes for multi-process tests: spawn with output to a file, signal, wait.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#ifndef BEACONLOC_TEST_TIME_SCALE
#define BEACONLOC_TEST_TIME_SCALE 1
#endif

namespace beaconloc::testing {

// How much longer waits are under the sanitizers (BEACONLOC_SANITIZE: the instrumented processes
// run a few times slower); 1 otherwise. ChildProcess::wait and run_command apply it themselves.
constexpr int kTimeScale = BEACONLOC_TEST_TIME_SCALE;
constexpr std::chrono::milliseconds scaled(std::chrono::milliseconds timeout) { return timeout * kTimeScale; }

class ChildProcess {
 public:
  // Starts argv[0] with the arguments; stdout and stderr go to log_path.
  ChildProcess(const std::vector<std::string>& argv, const std::string& log_path);
  ~ChildProcess();  // a child still running is killed (SIGKILL) and reaped
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  void signal(int sig);
  // Stops the child (SIGSTOP) and returns once every one of its threads has stopped (the kernel
  // reports the group stop to this parent), true; false if that is not seen within the timeout
  // (scaled() by kTimeScale) or the child has ended. kill() only queues the signal: a thread
  // running on another core goes on for a moment after it returns.
  bool stop(std::chrono::milliseconds timeout);
  // The exit code, or 128 + signal; nullopt on timeout (scaled() by kTimeScale). A sanitizer
  // report in the child's output is a test failure whatever the exit code.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  std::string log() const;

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::string log_path_;
};

// Runs to completion and returns (exit code, output); -1 on timeout (scaled() by kTimeScale).
std::pair<int, std::string> run_command(const std::vector<std::string>& argv,
                                        std::chrono::milliseconds timeout);

// Waits until pred() holds (true) or the timeout, scaled() by kTimeScale, passes (false): how a
// multi-process test waits for an event of another process, never for a fixed time.
template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + scaled(timeout);
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

}  // namespace beaconloc::testing
