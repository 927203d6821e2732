// SerialPort (plugins/gateway/serial/serial_port.hpp) on pseudo-terminals: what the master side
// writes is read from the slave's path; a master that closes makes the reader report the device
// gone (Linux hangs the slave up: poll says POLLHUP, read() says 0, older kernels EIO); a new pty
// behind the same symlink is opened again; bad bauds and paths that are no terminal are refused.
#include "serial_port.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pty.hpp"

namespace beaconloc::serial {
namespace {

using namespace std::chrono_literals;

class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/beaconloc_serial_XXXXXX";
    if (::mkdtemp(pattern) == nullptr) throw std::runtime_error("mkdtemp");
    path_ = pattern;
  }
  ~TempDir() {
    for (const std::string& f : files_) ::unlink(f.c_str());
    ::rmdir(path_.c_str());
  }
  std::string file(const std::string& name) {
    files_.push_back(path_ + "/" + name);
    return files_.back();
  }

 private:
  std::string path_;
  std::vector<std::string> files_;
};

// Everything the port reads within a deadline until `count` bytes are in.
std::vector<std::uint8_t> read_some(SerialPort& port, std::size_t count) {
  std::vector<std::uint8_t> got;
  std::uint8_t buffer[64];
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (got.size() < count && std::chrono::steady_clock::now() < deadline) {
    const auto r = port.read(buffer, sizeof buffer, 100ms);
    if (r.status == SerialPort::Status::kGone || r.status == SerialPort::Status::kClosed) break;
    got.insert(got.end(), buffer, buffer + r.size);
  }
  return got;
}

// The port reports gone within a deadline (data on the way is returned first, if the kernel kept it).
SerialPort::Status wait_gone(SerialPort& port) {
  std::uint8_t buffer[64];
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < deadline) {
    const auto r = port.read(buffer, sizeof buffer, 100ms);
    if (r.status == SerialPort::Status::kGone) return r.status;
  }
  return SerialPort::Status::kTimeout;
}

TEST(SerialPort, ReadsFromTheSlavePathWhatTheMasterWrites) {
  Pty pty;
  SerialPort port(pty.path(), 115200);
  const auto opened = port.open();
  ASSERT_TRUE(opened.ok()) << opened.message;
  ASSERT_TRUE(port.is_open());
  const std::vector<std::uint8_t> bytes = {0xB7, 0x4C, 0x00, 0x0A, 0x0D, 0x11, 0x13, 0x03, 0x7F, 0xFF};
  pty.write(bytes);  // raw mode: no byte translated, none taken as flow control or a signal
  EXPECT_EQ(read_some(port, bytes.size()), bytes);
}

TEST(SerialPort, AReadWithNothingToReadTimesOut) {
  Pty pty;
  SerialPort port(pty.path(), 9600);
  ASSERT_TRUE(port.open().ok());
  std::uint8_t buffer[8];
  const auto start = std::chrono::steady_clock::now();
  const auto r = port.read(buffer, sizeof buffer, 50ms);
  EXPECT_EQ(r.status, SerialPort::Status::kTimeout);
  EXPECT_EQ(r.size, 0u);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 45ms);
  EXPECT_TRUE(port.is_open());
}

// What Linux reports when a pty's master closes: the slave is hung up, poll() gives POLLHUP, and
// read() gives 0 (older kernels: EIO). The port says gone, once, and is closed.
TEST(SerialPort, AClosedMasterMakesTheReaderReportGone) {
  {
    Pty pty;
    const int raw = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    ASSERT_GE(raw, 0);
    pty.close_master();
    pollfd pfd{raw, POLLIN, 0};
    ASSERT_EQ(::poll(&pfd, 1, 1000), 1);
    EXPECT_NE(pfd.revents & POLLHUP, 0);
    std::uint8_t byte;
    const ssize_t n = ::read(raw, &byte, 1);
    const int e = errno;
    EXPECT_TRUE(n == 0 || (n < 0 && e == EIO)) << n << " " << std::strerror(e);
    ::close(raw);
  }
  Pty pty;
  SerialPort port(pty.path(), 115200);
  ASSERT_TRUE(port.open().ok());
  pty.close_master();
  EXPECT_EQ(wait_gone(port), SerialPort::Status::kGone);
  EXPECT_FALSE(port.is_open());
  EXPECT_TRUE(port.last_error() == 0 || port.last_error() == EIO) << port.last_error();
  std::uint8_t buffer[8];
  EXPECT_EQ(port.read(buffer, sizeof buffer, 10ms).status, SerialPort::Status::kClosed);
}

// The gateway's loop: the device goes away, open() fails while nothing is there, and a new
// device appearing at the same (symlink) path is opened and read.
TEST(SerialPort, ReopensWhenANewPtyAppearsAtTheSymlinkPath) {
  TempDir dir;
  const std::string link = dir.file("receiver");
  const std::string staging = dir.file("receiver.new");
  auto point_link_at = [&](const std::string& target) {
    ::unlink(staging.c_str());
    ASSERT_EQ(::symlink(target.c_str(), staging.c_str()), 0);
    ASSERT_EQ(::rename(staging.c_str(), link.c_str()), 0);  // atomic, as udev replaces its links
  };
  auto first = std::make_unique<Pty>();
  point_link_at(first->path());
  SerialPort port(link, 921600);
  ASSERT_TRUE(port.open().ok());
  first->write({1, 2, 3});
  EXPECT_EQ(read_some(port, 3), (std::vector<std::uint8_t>{1, 2, 3}));
  first.reset();
  EXPECT_EQ(wait_gone(port), SerialPort::Status::kGone);

  ::unlink(link.c_str());
  const auto missing = port.open();
  EXPECT_EQ(missing.failure, SerialPort::OpenFailure::kMissing);
  EXPECT_NE(missing.message.find(link), std::string::npos);
  EXPECT_FALSE(port.is_open());

  Pty second;
  point_link_at(second.path());
  const auto reopened = port.open();
  ASSERT_TRUE(reopened.ok()) << reopened.message;
  second.write({4, 5, 6, 7});
  EXPECT_EQ(read_some(port, 4), (std::vector<std::uint8_t>{4, 5, 6, 7}));
}

TEST(SerialPort, AnUnsupportedBaudIsRefusedNamingTheValueAndTheRatesAllowed) {
  for (std::uint32_t baud : {0u, 1200u, 12345u, 250000u, 4000000u}) {
    try {
      SerialPort port("/dev/null", baud);
      ADD_FAILURE() << baud << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::to_string(baud)), std::string::npos) << message;
      EXPECT_NE(message.find("9600, 19200, 38400, 57600, 115200"), std::string::npos) << message;
      EXPECT_NE(message.find("921600, 1000000"), std::string::npos) << message;
      EXPECT_NE(message.find("3000000"), std::string::npos) << message;
    }
  }
  for (std::uint32_t baud : SerialPort::supported_bauds()) EXPECT_NO_THROW(SerialPort("/dev/null", baud));
}

TEST(SerialPort, APathThatIsNotATerminalIsRefusedNamingItAndTheReason) {
  TempDir dir;
  const std::string plain = dir.file("plain");
  std::FILE* f = std::fopen(plain.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  for (const std::string& path : {std::string("/dev/null"), plain}) {
    SerialPort port(path, 115200);
    const auto r = port.open();
    EXPECT_EQ(r.failure, SerialPort::OpenFailure::kNotATerminal) << r.message;
    EXPECT_NE(r.message.find(path), std::string::npos) << r.message;
    EXPECT_NE(r.message.find(std::strerror(ENOTTY)), std::string::npos) << r.message;
    EXPECT_FALSE(port.is_open());
  }
  SerialPort missing(dir.file("nothing-here"), 115200);
  const auto r = missing.open();
  EXPECT_EQ(r.failure, SerialPort::OpenFailure::kMissing);
  EXPECT_EQ(r.error_number, ENOENT);
  EXPECT_NE(r.message.find(std::strerror(ENOENT)), std::string::npos) << r.message;
}

// A device node the user may not open. Root opens anything, so as root the open is tried from a
// child process that has given up root for "nobody" (65534).
TEST(SerialPort, APermissionProblemIsReportedAsSuch) {
  Pty pty;
  ASSERT_EQ(::chmod(pty.path().c_str(), 0), 0);
  auto try_open = [&] {
    SerialPort port(pty.path(), 115200);
    const auto r = port.open();
    return r.failure == SerialPort::OpenFailure::kPermissionDenied && r.error_number == EACCES &&
           r.message.find(pty.path()) != std::string::npos;
  };
  if (::geteuid() != 0) {
    EXPECT_TRUE(try_open());
    return;
  }
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const bool dropped = ::setgid(65534) == 0 && ::setuid(65534) == 0;
    ::_exit(!dropped ? 2 : try_open() ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: could not drop root; 1: not refused as permission_denied";
}

// The simulator's side: what the port writes comes out of the master.
TEST(SerialPort, WritesReachTheMaster) {
  Pty pty;
  SerialPort port(pty.path(), 115200);
  ASSERT_TRUE(port.open().ok());
  const std::vector<std::uint8_t> bytes(300, 0x5A);
  const auto w = port.write(bytes.data(), bytes.size(), 1000ms);
  EXPECT_EQ(w.status, SerialPort::Status::kData);
  EXPECT_EQ(w.size, bytes.size());
  std::vector<std::uint8_t> got;
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (got.size() < bytes.size() && std::chrono::steady_clock::now() < deadline) {
    pollfd pfd{pty.master(), POLLIN, 0};
    if (::poll(&pfd, 1, 100) != 1) continue;
    std::uint8_t buffer[512];
    const ssize_t n = ::read(pty.master(), buffer, sizeof buffer);
    if (n > 0) got.insert(got.end(), buffer, buffer + n);
  }
  EXPECT_EQ(got, bytes);
}

// RAII: the descriptor moves with the port and closes with it (the master then sees its slave
// hang up); a moved-from port is closed.
TEST(SerialPort, MovesItsDescriptorAndClosesItOnDestruction) {
  Pty pty;
  auto hung_up = [&] {
    pollfd pfd{pty.master(), POLLIN, 0};
    return ::poll(&pfd, 1, 0) == 1 && (pfd.revents & POLLHUP) != 0;
  };
  {
    SerialPort port(pty.path(), 115200);
    ASSERT_TRUE(port.open().ok());
    EXPECT_FALSE(hung_up());
    SerialPort moved(std::move(port));
    EXPECT_TRUE(moved.is_open());
    EXPECT_FALSE(port.is_open());  // NOLINT(bugprone-use-after-move): the moved-from state is the point
    SerialPort assigned("/dev/null", 9600);
    assigned = std::move(moved);
    EXPECT_TRUE(assigned.is_open());
    EXPECT_EQ(assigned.path(), pty.path());
    EXPECT_FALSE(hung_up());
  }
  EXPECT_TRUE(hung_up());
}

}  // namespace
}  // namespace beaconloc::serial
