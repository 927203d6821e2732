#pragma once
// Helpers of the fuzz targets whose parsers read files: the input split into the files' texts,
// and a scratch directory of this process to write them into.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace beaconloc::fuzz {

// The parts of the input between lines "%%" (the separator is "\n%%\n").
inline std::vector<std::string> split_parts(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n%%\n";
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (std::size_t at = input.find(separator); at != std::string::npos; at = input.find(separator, from)) {
    parts.push_back(input.substr(from, at - from));
    from = at + separator.size();
  }
  parts.push_back(input.substr(from));
  return parts;
}

// <tmp>/beaconloc-fuzz-<pid>, created on first use. <tmp> is $TMPDIR, else /dev/shm where there
// is one (on a disk, ext4 flushes every file rewritten in place: 200 executions a second instead
// of thousands), else /tmp. libFuzzer leaves without running atexit handlers: scripts/fuzz.sh
// points TMPDIR into a directory of its own, and removes it.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::error_code ignored;
    const std::filesystem::path base = tmp && *tmp                                          ? tmp
                                       : std::filesystem::is_directory("/dev/shm", ignored) ? "/dev/shm"
                                                                                            : "/tmp";
    std::filesystem::path d = base / ("beaconloc-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes `text` to dir/name, or removes dir/name when the input has no such part.
inline void write_or_remove(const std::filesystem::path& file, const std::vector<std::string>& parts,
                            std::size_t index) {
  if (index < parts.size()) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << parts[index];
  } else {
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
  }
}

// The recording's files in scratch_dir(), one per part in the order of `names`: a part that is
// empty or missing is an absent file (a recording of pulses has no ranges.csv).
inline void write_recording(const std::vector<std::string>& parts, const std::vector<const char*>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i < parts.size() && parts[i].empty()) {
      std::error_code ignored;
      std::filesystem::remove(scratch_dir() / names[i], ignored);
    } else {
      write_or_remove(scratch_dir() / names[i], parts, i);
    }
  }
}

}  // namespace beaconloc::fuzz
