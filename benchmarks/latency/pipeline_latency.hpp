#pragma once
// The pipeline's latency: this process plays the gateway and reads the poses, with `beaconloc
// decoder` and `beaconloc localizer` as child processes; each timed TOF is matched to a pose.
#include <cstddef>
#include <vector>

#include "common.hpp"

namespace beaconloc::latency {

struct PipelineResult {
  std::vector<double> latency_us;      // one per matched timed TOF
  std::size_t timed = 0;               // TOFs timed: the first of each slot, inside the measured window
  std::size_t correction_matches = 0;  // matched pose repeats the previous pose's stamp
  std::size_t tofs_written = 0;
  std::size_t poses = 0;
  double pose_rate_hz = 0.0;
  // The decoder's and localizer's CPU time over the measured window, and the samples (TOFs and
  // odometry) written to them in it.
  double children_cpu_s = 0.0;
  std::size_t window_samples = 0;
  double window_s = 0.0;
};

// One run on st.pipeline_domain over transport t: st.warmup_s unmeasured, st.duration_s measured,
// then a 0.5 s tail for the last poses.
PipelineResult run_pipeline(const Settings& st, const Transport& t);

}  // namespace beaconloc::latency
