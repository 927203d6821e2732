// The benchmark's child processes: the --exec-child-of trampoline (SIGTERM to the child when the
// benchmark dies), the clean stop, and the check that none has ended.
#include "child.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "bench_support.hpp"

namespace beaconloc::latency {

namespace {

// {self, --exec-child-of, <this pid>, argv...}: the child runs argv through the trampoline.
std::vector<std::string> through_trampoline(const std::vector<std::string>& argv) {
  std::vector<std::string> out{bench::self_executable(), kExecChildOf, std::to_string(::getpid())};
  out.insert(out.end(), argv.begin(), argv.end());
  return out;
}

}  // namespace

int exec_child_of(int argc, char** argv) {
  if (argc < 4) return 127;
  // PR_SET_PDEATHSIG survives execv; the parent may have died before it was set.
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != static_cast<pid_t>(std::atol(argv[2]))) return 127;
  ::execv(argv[3], argv + 3);
  std::fprintf(stderr, "latency: cannot exec %s\n", argv[3]);
  return 127;
}

Child::Child(std::string name, const std::vector<std::string>& argv, const std::string& log_path)
    : name_(std::move(name)), log_path_(log_path), process_(through_trampoline(argv), log_path) {}

std::optional<int> Child::stop() {
  if (const auto s = poll()) return s;
  process_.signal(SIGTERM);
  if (const auto s = process_.wait(std::chrono::seconds(10))) return s;
  std::fprintf(stderr, "latency: %s (pid %d) ignored SIGTERM for 10 s: SIGKILL\n", name_.c_str(),
               static_cast<int>(process_.pid()));
  process_.signal(SIGKILL);
  return process_.wait(std::chrono::seconds(5));  // if still running, ~ChildProcess reaps it
}

void require_alive(const std::vector<Child*>& children) {
  for (auto* c : children) {
    if (const auto s = c->poll()) {
      throw std::runtime_error(c->name() + " (pid " + std::to_string(c->pid()) + ") exited with status " +
                               std::to_string(*s) + "; log: " + c->log_path());
    }
  }
}

}  // namespace beaconloc::latency
