#pragma once
// One transport's figures from a run's samples (or the medians over runs): percentiles, ratios,
// the table rows printed and the CSV rows (benchmark,case,metric,value,unit; the case is the
// transport).
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "pipeline_latency.hpp"
#include "raw_hop.hpp"

namespace beaconloc::latency {

struct Stats {
  std::size_t n = 0;
  double p50 = NAN, p99 = NAN, max = NAN;
};

struct Figures {
  Stats pipeline, hop, b2b;
  double ratio50 = NAN, ratio99 = NAN;          // pipeline / (3 x paced hop)
  double b2b_ratio50 = NAN, b2b_ratio99 = NAN;  // pipeline / (3 x back-to-back hop)
  double matched = NAN, corrections = NAN;      // fractions of timed TOFs, of matches
  std::size_t timed = 0, tofs = 0, poses = 0, pings = 0, lost = 0;
  double pose_rate_hz = NAN;
  // CPU: the decoder's and localizer's per sample written to them (TOFs and odometry) and in % of
  // one core, over the measured window; the echo's per paced round trip (one read, one write).
  double pipeline_cpu_us_per_sample = NAN, pipeline_cpu_percent = NAN, echo_cpu_us_per_round_trip = NAN;
};

// Nearest-rank p50 and p99 (bench::percentile) and the max.
Stats stats_of(const std::vector<double>& v);
Figures figures_of(const PipelineResult& pipeline, const HopResult& hop);
// Element-wise medians over runs (bench::median, each figure on its own; the ratio is the median
// of each run's own ratio, pipeline and hop from the same run).
Figures median_of(const std::vector<Figures>& runs);

void print_header(const std::string& title);
void print_figures(const std::string& transport, const Figures& f);
// Appends the figures' rows to the CSV file (its header written when the file is new).
void append_csv(const std::string& path, const std::string& benchmark, const std::string& transport,
                const Figures& f);

}  // namespace beaconloc::latency
