#pragma once
// A serial device (USB CDC or UART) in raw mode, 8N1, no flow control, read with poll(): the
// receiver module's line. A device that goes away (unplugged, its pty master closed) reports
// kGone and is closed; open() may be called again (the gateway retries every 250 ms or so).
// Opening errors are a typed result naming the path and the system's reason; an unsupported baud
// rate is a configuration error, thrown by the constructor.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace beaconloc::serial {

class SerialPort {
 public:
  enum class OpenFailure : std::uint8_t {
    kNone,
    kMissing,           // ENOENT, ENODEV, ENXIO: no such device (yet)
    kPermissionDenied,  // EACCES, EPERM
    kNotATerminal,      // opened, but not a tty (tcgetattr: ENOTTY)
    kOther,             // anything else (EBUSY, ...): message says what
  };
  struct OpenResult {
    OpenFailure failure = OpenFailure::kNone;
    int error_number = 0;
    std::string message;  // names the path and strerror; empty on success
    bool ok() const { return failure == OpenFailure::kNone; }
  };

  enum class Status : std::uint8_t {
    kData,     // size bytes read (or written)
    kTimeout,  // nothing within the timeout (or a signal interrupted the wait)
    kGone,     // hangup or an I/O error: the device went away; the port is now closed
    kClosed,   // the port is not open
  };
  struct IoResult {
    std::size_t size = 0;
    Status status = Status::kClosed;
  };

  // Throws std::invalid_argument naming the value and the rates allowed for any other baud.
  SerialPort(std::string path, std::uint32_t baud);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;

  // Opens the path (O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC) and sets raw 8N1 at the baud
  // rate. Open already: closes first.
  OpenResult open();
  void close();
  bool is_open() const { return fd_ >= 0; }

  // Up to cap bytes, waiting at most timeout for the first.
  IoResult read(std::uint8_t* buffer, std::size_t cap, std::chrono::milliseconds timeout);
  // All size bytes unless timeout passes first (the simulator's side of a pty).
  IoResult write(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds timeout);

  const std::string& path() const { return path_; }
  std::uint32_t baud() const { return baud_; }
  // errno of the error that made the port gone (0 for a hangup seen as POLLHUP or end of file).
  int last_error() const { return last_error_; }

  // The rates a SerialPort accepts, ascending, and them as text ("4800, 9600, ...").
  static std::vector<std::uint32_t> supported_bauds();
  static std::string supported_bauds_text();

 private:
  IoResult gone(int error_number);

  std::string path_;
  std::uint32_t baud_;
  int fd_ = -1;
  int last_error_ = 0;
};

const char* to_string(SerialPort::OpenFailure failure);
const char* to_string(SerialPort::Status status);

}  // namespace beaconloc::serial
