#include "serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace beaconloc::serial {
namespace {

struct Rate {
  std::uint32_t baud;
  speed_t constant;
};
// Linux's termios rates from 4800 (Marvelmind's slowest UART setting) to 3 Mbit/s.
constexpr Rate kRates[] = {
    {4800, B4800},       {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
    {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},
    {921600, B921600},   {1000000, B1000000}, {1152000, B1152000}, {1500000, B1500000}, {2000000, B2000000},
    {2500000, B2500000}, {3000000, B3000000},
};

bool speed_of(std::uint32_t baud, speed_t* constant) {
  for (const Rate& r : kRates) {
    if (r.baud == baud) {
      *constant = r.constant;
      return true;
    }
  }
  return false;
}

int poll_ms(std::chrono::milliseconds timeout) {
  if (timeout.count() < 0) return 0;
  if (timeout.count() > 1'000'000'000) return 1'000'000'000;
  return static_cast<int>(timeout.count());
}

}  // namespace

SerialPort::SerialPort(std::string path, std::uint32_t baud) : path_(std::move(path)), baud_(baud) {
  speed_t unused;
  if (!speed_of(baud, &unused)) {
    throw std::invalid_argument("serial port " + path_ + ": unsupported baud rate " + std::to_string(baud) +
                                " (supported: " + supported_bauds_text() + ")");
  }
}

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : path_(std::move(other.path_)),
      baud_(other.baud_),
      fd_(std::exchange(other.fd_, -1)),
      last_error_(other.last_error_) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close();
    path_ = std::move(other.path_);
    baud_ = other.baud_;
    fd_ = std::exchange(other.fd_, -1);
    last_error_ = other.last_error_;
  }
  return *this;
}

std::vector<std::uint32_t> SerialPort::supported_bauds() {
  std::vector<std::uint32_t> bauds;
  for (const Rate& r : kRates) bauds.push_back(r.baud);
  return bauds;
}

std::string SerialPort::supported_bauds_text() {
  std::string text;
  for (const Rate& r : kRates) {
    if (!text.empty()) text += ", ";
    text += std::to_string(r.baud);
  }
  return text;
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);  // errors on close of a tty carry nothing we could act on
  fd_ = -1;
}

SerialPort::OpenResult SerialPort::open() {
  close();
  last_error_ = 0;
  OpenResult result;
  auto fail = [&](OpenFailure failure, int error_number, const char* what) {
    result.failure = failure;
    result.error_number = error_number;
    result.message = "serial port " + path_ + ": " + what + ": " + std::strerror(error_number);
    close();
    return result;
  };
  fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int e = errno;
    if (e == ENOENT || e == ENODEV || e == ENXIO) return fail(OpenFailure::kMissing, e, "cannot open");
    if (e == EACCES || e == EPERM) return fail(OpenFailure::kPermissionDenied, e, "cannot open");
    return fail(OpenFailure::kOther, e, "cannot open");
  }
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) {
    const int e = errno;
    if (e == ENOTTY || e == EINVAL) return fail(OpenFailure::kNotATerminal, e, "not a terminal");
    return fail(OpenFailure::kOther, e, "tcgetattr");
  }
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;  // no modem control lines: a UART has none, CDC ignores them
  tio.c_cflag &= ~(CSIZE | PARENB | CSTOPB | CRTSCTS);
  tio.c_cflag |= CS8;
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  // poll() decides when to read; a read then takes what is there.
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  speed_t speed = B9600;
  speed_of(baud_, &speed);  // checked by the constructor
  if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0) {
    return fail(OpenFailure::kOther, errno, "cfsetspeed");
  }
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) return fail(OpenFailure::kOther, errno, "tcsetattr");
  // Bytes that waited in the driver while the port was closed would arrive late all at once and
  // make the device clock's first offset wrong: the line is read from now on.
  ::tcflush(fd_, TCIFLUSH);
  return result;
}

SerialPort::IoResult SerialPort::gone(int error_number) {
  last_error_ = error_number;
  close();
  return {0, Status::kGone};
}

SerialPort::IoResult SerialPort::read(std::uint8_t* buffer, std::size_t cap,
                                      std::chrono::milliseconds timeout) {
  if (fd_ < 0) return {0, Status::kClosed};
  pollfd pfd{fd_, POLLIN, 0};
  const int ready = ::poll(&pfd, 1, poll_ms(timeout));
  if (ready < 0) {
    if (errno == EINTR) return {0, Status::kTimeout};
    return gone(errno);
  }
  if (ready == 0) return {0, Status::kTimeout};
  // Data first: bytes that came before a hangup are still the device's.
  if ((pfd.revents & POLLIN) != 0 || (pfd.revents & (POLLHUP | POLLERR)) != 0) {
    const ssize_t n = ::read(fd_, buffer, cap);
    if (n > 0) return {static_cast<std::size_t>(n), Status::kData};
    if (n == 0) return gone(0);  // end of file on a tty: the other end hung up
    const int e = errno;
    if (e == EAGAIN || e == EINTR) {
      // Readable yet nothing to read: only a hangup without data explains it.
      if ((pfd.revents & (POLLHUP | POLLERR)) != 0) return gone(0);
      return {0, Status::kTimeout};
    }
    // EIO: the tty layer's word for a hung-up other end (a pty whose master closed, a USB CDC
    // device unplugged); ENXIO, ENODEV: the driver gone under the descriptor. Any other error
    // leaves the descriptor of no more use either.
    return gone(e);
  }
  return gone(0);  // POLLNVAL
}

SerialPort::IoResult SerialPort::write(const std::uint8_t* data, std::size_t size,
                                       std::chrono::milliseconds timeout) {
  if (fd_ < 0) return {0, Status::kClosed};
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd_, data + written, size - written);
    if (n > 0) {
      written += static_cast<std::size_t>(n);
      continue;
    }
    const int e = errno;
    if (n < 0 && e != EAGAIN && e != EINTR) return gone(e);
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd pfd{fd_, POLLOUT, 0};
    const int ready = ::poll(&pfd, 1, poll_ms(left));
    if (ready < 0 && errno != EINTR) return gone(errno);
    if (ready > 0 && (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 && (pfd.revents & POLLOUT) == 0) {
      return gone(0);
    }
  }
  return {written, written == size ? Status::kData : Status::kTimeout};
}

const char* to_string(SerialPort::OpenFailure failure) {
  switch (failure) {
    case SerialPort::OpenFailure::kNone:
      return "none";
    case SerialPort::OpenFailure::kMissing:
      return "missing";
    case SerialPort::OpenFailure::kPermissionDenied:
      return "permission_denied";
    case SerialPort::OpenFailure::kNotATerminal:
      return "not_a_terminal";
    case SerialPort::OpenFailure::kOther:
      return "other";
  }
  return "unknown_open_failure";
}

const char* to_string(SerialPort::Status status) {
  switch (status) {
    case SerialPort::Status::kData:
      return "data";
    case SerialPort::Status::kTimeout:
      return "timeout";
    case SerialPort::Status::kGone:
      return "gone";
    case SerialPort::Status::kClosed:
      return "closed";
  }
  return "unknown_status";
}

}  // namespace beaconloc::serial
