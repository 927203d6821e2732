// The participants' stop on signals (dds/stop_signal.hpp): the first SIGINT or SIGTERM asks for a
// clean stop; the same signal again ends a process whose clean stop is stuck (issue 23: a
// localizer spinning in its listener ignored SIGTERM and SIGINT, only SIGKILL stopped it).
#include "beaconloc/dds/stop_signal.hpp"

#include <gtest/gtest.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

namespace beaconloc {
namespace {

// A child that takes the handlers and never stops by itself (as a process whose teardown waits
// on a stuck thread): after each signal it handles it writes 's' to `report` once a stop was
// asked for ('n' before). The parent sends one signal at a time and reads the answer, so each
// signal is handled before the next is sent.
struct StuckChild {
  pid_t pid = -1;
  int from_child = -1;
  StuckChild() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid = ::fork();
    if (pid == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlives the test
      if (::getppid() == 1) ::_exit(92);
      ::close(fds[0]);
      dds::install_stop_handlers();
      // Signals wait, blocked, until sigsuspend: none is handled between two waits.
      sigset_t stops, none;
      sigemptyset(&stops);
      sigemptyset(&none);
      for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) sigaddset(&stops, sig);
      sigprocmask(SIG_BLOCK, &stops, nullptr);
      if (::write(fds[1], "r", 1) != 1) ::_exit(90);
      for (;;) {
        ::sigsuspend(&none);  // returns after each handled signal
        if (::write(fds[1], dds::stop_requested() ? "s" : "n", 1) != 1) ::_exit(91);
      }
    }
    ::close(fds[1]);
    from_child = fds[0];
  }
  ~StuckChild() {
    if (pid > 0 && ::kill(pid, SIGKILL) == 0) ::waitpid(pid, nullptr, 0);
    if (from_child >= 0) ::close(from_child);
  }
  // The child's answer to `sig`: 's' (it asked for a stop and runs on), or '\0' once it ended.
  char signal(int sig) {
    ::kill(pid, sig);
    char c = 0;
    return ::read(from_child, &c, 1) == 1 ? c : '\0';
  }
  char first_word() {
    char c = 0;
    return ::read(from_child, &c, 1) == 1 ? c : '\0';
  }
  int wait_status() {
    int status = 0;
    ::waitpid(pid, &status, 0);
    pid = -1;
    return status;
  }
};

TEST(StopSignal, TheSameSignalTwiceEndsAProcessWhoseCleanStopIsStuck) {
  for (int sig : {SIGTERM, SIGINT}) {
    StuckChild child;
    ASSERT_GT(child.pid, 0);
    ASSERT_EQ(child.first_word(), 'r');
    EXPECT_EQ(child.signal(sig), 's') << "the first signal asks for a clean stop, and the child runs on";
    EXPECT_EQ(child.signal(sig), '\0') << "the second one ends it";
    const int status = child.wait_status();
    EXPECT_TRUE(WIFEXITED(status)) << sig;
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
  }
}

TEST(StopSignal, ADifferentSignalAfterTheFirstStillWaitsForTheCleanStop) {
  // Ctrl-C reaches a whole process group, whose parent then SIGTERMs its children once to stop
  // them in order: that must not cut their clean stop short. Nor may SIGPIPE, raised by every
  // write to a closed pipe.
  StuckChild child;
  ASSERT_GT(child.pid, 0);
  ASSERT_EQ(child.first_word(), 'r');
  EXPECT_EQ(child.signal(SIGINT), 's');
  EXPECT_EQ(child.signal(SIGTERM), 's');
  EXPECT_EQ(child.signal(SIGPIPE), 's');
  EXPECT_EQ(child.signal(SIGPIPE), 's');
  EXPECT_EQ(child.signal(SIGHUP), 's');
}

}  // namespace
}  // namespace beaconloc
