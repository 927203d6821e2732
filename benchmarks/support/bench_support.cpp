#include "bench_support.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace beaconloc::bench {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double status_kb(pid_t pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1));
  }
  return kNaN;
}
}  // namespace

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(q * static_cast<double>(values.size()));
  const auto index = static_cast<std::size_t>(std::clamp(rank, 1.0, static_cast<double>(values.size()))) - 1;
  return values[index];
}

double process_cpu_s(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return kNaN;
  // Fields after the command name (which may hold spaces, in parentheses): utime is the 14th
  // field of the line, stime the 15th, in clock ticks.
  std::istringstream rest(stat.substr(stat.rfind(')') + 2));
  std::string field;
  double utime = 0.0, stime = 0.0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double resident_mb(pid_t pid) { return status_kb(pid, "VmRSS") / 1024.0; }
double peak_resident_mb(pid_t pid) { return status_kb(pid, "VmHWM") / 1024.0; }

double log_field(const std::string& log, const std::string& key) {
  const std::string needle = key + "=";
  std::size_t at = std::string::npos, from = 0;
  while (true) {
    const std::size_t found = log.find(needle, from);
    if (found == std::string::npos) break;
    if (found == 0 || log[found - 1] == ' ' || log[found - 1] == '\n') at = found;
    from = found + 1;
  }
  if (at == std::string::npos) return kNaN;
  try {
    return std::stod(log.substr(at + needle.size()));
  } catch (const std::exception&) {
    return kNaN;
  }
}

std::string self_executable() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

void Results::add(const std::string& metric, double value, const std::string& unit) {
  rows_.push_back({metric, value, unit});
}

void Results::print() const {
  std::printf("%s %s\n", benchmark_.c_str(), case_.c_str());
  for (const auto& r : rows_) std::printf("  %-32s %12.4g %s\n", r.metric.c_str(), r.value, r.unit.c_str());
  std::fflush(stdout);
}

void Results::append_csv(const std::string& path) const {
  const bool fresh = !std::filesystem::exists(path) || std::filesystem::file_size(path) == 0;
  std::ofstream out(path, std::ios::app);
  if (fresh) out << "benchmark,case,metric,value,unit\n";
  out.precision(6);
  for (const auto& r : rows_)
    out << benchmark_ << ',' << case_ << ',' << r.metric << ',' << r.value << ',' << r.unit << '\n';
}

}  // namespace beaconloc::bench
