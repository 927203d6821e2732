#pragma once
// What the multi-process benchmarks share: percentiles, a process's CPU time and resident memory
// from /proc, the figures printed as a table and appended to the suite's CSV.
#include <sys/types.h>

#include <string>
#include <utility>
#include <vector>

namespace beaconloc::bench {

// The q-quantile (0..1) of the values, nearest rank; NaN when there are none.
double percentile(std::vector<double> values, double q);
// The median of the values; NaN when there are none.
inline double median(std::vector<double> values) { return percentile(std::move(values), 0.5); }

// User + system CPU seconds of a process so far (/proc/<pid>/stat); NaN if it is gone.
double process_cpu_s(pid_t pid);
// Resident set (VmRSS) and its peak (VmHWM) of a process, in MB (2^20 bytes); NaN if gone.
double resident_mb(pid_t pid);
double peak_resident_mb(pid_t pid);

// The number after "key=" in a line of a child's log (the last one); NaN when absent.
double log_field(const std::string& log, const std::string& key);

// This program's own path, to start it again in another role.
std::string self_executable();

// One benchmark case's figures: printed as "metric value unit" lines, appended to a CSV as rows
// benchmark,case,metric,value,unit (the header is written when the file is new).
class Results {
 public:
  Results(std::string benchmark, std::string case_name)
      : benchmark_(std::move(benchmark)), case_(std::move(case_name)) {}
  void add(const std::string& metric, double value, const std::string& unit);
  void print() const;
  void append_csv(const std::string& path) const;

 private:
  struct Row {
    std::string metric;
    double value;
    std::string unit;
  };
  std::string benchmark_;
  std::string case_;
  std::vector<Row> rows_;
};

}  // namespace beaconloc::bench
