#pragma once
// The benchmark's child processes (decoder, localizer, echo peer): a testing::ChildProcess with a
// name and its log's path, started through this executable (--exec-child-of) so that it gets
// SIGTERM if the benchmark dies, and stopped cleanly (SIGTERM, then SIGKILL after 10 s) by stop()
// and by its destructor, so errors and Ctrl-C (Stopped) leave none running.
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common.hpp"
#include "process.hpp"

namespace beaconloc::latency {

// The first argument of this executable that makes it the trampoline of exec_child_of().
constexpr const char* kExecChildOf = "--exec-child-of";

// The trampoline: argv is {self, "--exec-child-of", <parent pid>, program, args...}. Asks for
// SIGTERM when the parent dies, then execs the program (whose pid stays the child's). Returns
// only on failure (127).
int exec_child_of(int argc, char** argv);

class Child {
 public:
  // Starts argv (argv[0]: the program) with stdout and stderr in log_path.
  Child(std::string name, const std::vector<std::string>& argv, const std::string& log_path);
  ~Child() { stop(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  const std::string& name() const { return name_; }
  pid_t pid() const { return process_.pid(); }
  const std::string& log_path() const { return log_path_; }
  // Exit status (code, or 128 + signal) once it has ended; nullopt while running.
  std::optional<int> poll() { return process_.wait(std::chrono::milliseconds(0)); }
  // SIGTERM (the participants leave cleanly and remove their shared-memory files), then SIGKILL
  // if it has not ended within 10 s. Returns the exit status.
  std::optional<int> stop();

 private:
  std::string name_;
  std::string log_path_;
  testing::ChildProcess process_;
};

// Throws naming the first child that has ended (with its status and log).
void require_alive(const std::vector<Child*>& children);

// Waits until cond() holds; throws Stopped on a stop request, or when a child ends or the timeout
// passes.
template <class Cond>
void wait_until(const char* what, Cond cond, std::chrono::milliseconds timeout,
                const std::vector<Child*>& children) {
  const auto end = Clock::now() + timeout;
  while (!cond()) {
    check_stop();
    require_alive(children);
    if (Clock::now() > end) throw std::runtime_error(std::string("timed out waiting for ") + what);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace beaconloc::latency
