#include "beaconloc/core/calibration_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <sys/stat.h>

#include <cerrno>
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/decimal.hpp"

namespace beaconloc {
namespace {

constexpr std::string_view kHeader = "beaconloc-calibration 1";

std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

// The shortest text that reads back bit for bit, whatever the process's locale.
std::string number(double v) {
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, r.ptr);
}

std::string checksum_line(std::string_view body) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "checksum %016" PRIx64 "\n", fnv1a64(body));
  return buffer;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (start <= line.size()) {
    const std::size_t space = line.find(' ', start);
    const std::size_t end = space == std::string_view::npos ? line.size() : space;
    out.push_back(line.substr(start, end - start));  // an empty token (two spaces) fails to parse
    if (space == std::string_view::npos) break;
    start = space + 1;
  }
  return out;
}

CalibrationFileResult malformed(std::size_t line, const std::string& what) {
  return {CalibrationFileProblem::kMalformed, "line " + std::to_string(line) + ": " + what};
}

template <class T>
bool read(std::string_view token, T& out) {
  return parse_decimal(token, out) == NumberError::kNone;
}

CalibrationFileResult system_failure(const std::string& call, const std::string& path) {
  return {CalibrationFileProblem::kWriteFailed, call + " " + path + ": " + std::strerror(errno)};
}

// write(2) until every byte is out (a write may be partial).
bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

const char* to_string(CalibrationFileProblem problem) {
  switch (problem) {
    case CalibrationFileProblem::kNone: return "none";
    case CalibrationFileProblem::kMissing: return "missing";
    case CalibrationFileProblem::kUnreadable: return "unreadable";
    case CalibrationFileProblem::kTooLarge: return "too_large";
    case CalibrationFileProblem::kMalformed: return "malformed";
    case CalibrationFileProblem::kChecksumMismatch: return "checksum_mismatch";
    case CalibrationFileProblem::kInvalid: return "invalid";
    case CalibrationFileProblem::kWriteFailed: return "write_failed";
  }
  return "unknown";
}

std::string format_calibration(const BeaconCalibration& calibration) {
  std::string body(kHeader);
  body += '\n';
  for (const GroupCalibration& g : calibration.groups) {
    body += "group " + std::to_string(g.group) + ' ' + std::to_string(g.stamp_ns);
    for (int i = 0; i < 4; ++i) body += ' ' + number(g.transform(i));
    body += ' ' + number(g.mean_error_m) + ' ' + std::to_string(g.beacons.size()) + '\n';
    for (const CalibratedBeacon& b : g.beacons) {
      body += "beacon " + std::to_string(b.id);
      for (int i = 0; i < 3; ++i) body += ' ' + number(b.position_map_m(i));
      body += ' ' + number(b.covariance_m2(0, 0)) + ' ' + number(b.covariance_m2(0, 1)) + ' ' +
              number(b.covariance_m2(1, 1)) + '\n';
    }
  }
  return body + checksum_line(body);
}

std::optional<BeaconCalibration> parse_calibration(const std::string& text, CalibrationFileResult* result) {
  CalibrationFileResult local;
  CalibrationFileResult& r = result ? *result : local;
  r = {};
  const auto fail = [&r](CalibrationFileResult why) {
    r = std::move(why);
    return std::nullopt;
  };
  if (text.size() > kMaxCalibrationFileBytes) return fail({CalibrationFileProblem::kTooLarge, ""});
  // The checksum line is the last; everything before it is the body it covers.
  if (text.empty() || text.back() != '\n') return fail(malformed(0, "does not end with a line break"));
  const std::size_t last_start = text.rfind('\n', text.size() - 2) + 1;  // npos + 1 = 0
  const std::string_view body(text.data(), last_start);
  const std::string_view last(text.data() + last_start, text.size() - last_start);
  if (last.substr(0, 9) != "checksum ") return fail(malformed(0, "no checksum line at the end"));
  if (last != checksum_line(body)) return fail({CalibrationFileProblem::kChecksumMismatch, std::string(last)});
  BeaconCalibration out;
  std::size_t line_number = 0;
  std::size_t expected_beacons = 0;
  std::size_t start = 0;
  while (start < body.size()) {
    const std::size_t end = body.find('\n', start);
    const std::string_view line = body.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (line_number == 1) {
      if (line != kHeader) return fail(malformed(1, "not a beaconloc calibration of version 1"));
      continue;
    }
    const std::vector<std::string_view> t = split(line);
    if (t[0] == "group" && t.size() == 9) {
      if (expected_beacons != 0) return fail(malformed(line_number, "the previous group lacks beacons"));
      GroupCalibration g;
      std::uint64_t count = 0;
      if (!read(t[1], g.group) || !read(t[2], g.stamp_ns) || !read(t[3], g.transform(0)) ||
          !read(t[4], g.transform(1)) || !read(t[5], g.transform(2)) || !read(t[6], g.transform(3)) ||
          !read(t[7], g.mean_error_m) || !read(t[8], count) || count == 0 || count > kMaxBeacons) {
        return fail(malformed(line_number, "a group line's numbers"));
      }
      expected_beacons = static_cast<std::size_t>(count);
      out.groups.push_back(std::move(g));
    } else if (t[0] == "beacon" && t.size() == 8) {
      if (expected_beacons == 0) return fail(malformed(line_number, "a beacon line outside a group"));
      CalibratedBeacon b;
      double xy = 0.0;
      if (!read(t[1], b.id) || !read(t[2], b.position_map_m(0)) || !read(t[3], b.position_map_m(1)) ||
          !read(t[4], b.position_map_m(2)) || !read(t[5], b.covariance_m2(0, 0)) || !read(t[6], xy) ||
          !read(t[7], b.covariance_m2(1, 1))) {
        return fail(malformed(line_number, "a beacon line's numbers"));
      }
      b.covariance_m2(0, 1) = b.covariance_m2(1, 0) = xy;
      out.groups.back().beacons.push_back(b);
      --expected_beacons;
    } else {
      return fail(malformed(line_number, "neither a group nor a beacon line"));
    }
  }
  if (line_number == 0) return fail(malformed(1, "no version line"));
  if (expected_beacons != 0) return fail(malformed(line_number, "the last group lacks beacons"));
  if (const CalibrationCheck check = check_calibration(out); !check.ok()) {
    return fail({CalibrationFileProblem::kInvalid, check.describe()});
  }
  return out;
}

CalibrationFileResult save_calibration(const std::string& path, const BeaconCalibration& calibration) {
  if (const CalibrationCheck check = check_calibration(calibration); !check.ok()) {
    return {CalibrationFileProblem::kInvalid, check.describe()};
  }
  const std::string text = format_calibration(calibration);
  // A temporary of its own (mkstemp: a new name, created exclusively, never through a link), so
  // that two savers never write into one file; removed on any failure.
  std::string temporary = path + ".tmp.XXXXXX";
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) return system_failure("mkstemp", temporary);
  const auto fail = [&temporary](const std::string& call) {
    const CalibrationFileResult r = system_failure(call, temporary);
    ::unlink(temporary.c_str());
    return r;
  };
  if (::fchmod(fd, 0644) != 0) {
    ::close(fd);
    return fail("fchmod");
  }
  const bool written = write_all(fd, text) && ::fsync(fd) == 0;
  const int saved_errno = errno;
  if (::close(fd) != 0 && written) return fail("close");
  if (!written) {
    errno = saved_errno;
    return fail("write");
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) return fail("rename");
  // The rename itself on the disk: the directory's entry flushed. Failing here, the new file is in
  // place (a reader finds it) but may not survive a power cut: said in the detail.
  const std::string directory = directory_of(path);
  const int dir = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  const bool synced = dir >= 0 && ::fsync(dir) == 0;
  if (dir >= 0) ::close(dir);
  if (!synced) {
    CalibrationFileResult r = system_failure("fsync", directory);
    r.detail += " (the new calibration is in place, its rename not yet on the disk)";
    return r;
  }
  return {};
}

std::optional<BeaconCalibration> load_calibration(const std::string& path, CalibrationFileResult* result) {
  CalibrationFileResult local;
  CalibrationFileResult& r = result ? *result : local;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    r = {errno == ENOENT ? CalibrationFileProblem::kMissing : CalibrationFileProblem::kUnreadable,
         path + ": " + std::strerror(errno)};
    return std::nullopt;
  }
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      r = {CalibrationFileProblem::kUnreadable, path + ": " + std::strerror(errno)};
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > kMaxCalibrationFileBytes) {
      r = {CalibrationFileProblem::kTooLarge, path};
      ::close(fd);
      return std::nullopt;
    }
  }
  ::close(fd);
  return parse_calibration(text, &r);
}

}  // namespace beaconloc
