#pragma once
// Records the EstimatorState topic (what estimators hold beside the pose, once a second: seed
// 002's speed of sound and cycle) for `run`, which writes it as estimator_state.csv:
// robot_id,stamp_ns,estimator,name,value,sigma, one row per value. A sample with a non-finite
// number is refused and counted, never recorded.
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/dds/participant.hpp"

namespace beaconloc {

struct EstimatorStateRow {
  std::string robot_id;
  StampNs stamp_ns = 0;
  std::string estimator;
  Estimator::StateValue value;
};

class EstimatorStateRecorder {
 public:
  explicit EstimatorStateRecorder(const dds::DdsOptions& dds);
  std::vector<EstimatorStateRow> rows() const;
  std::uint64_t refused() const;  // samples with a non-finite number

 private:
  mutable std::mutex mutex_;
  std::vector<EstimatorStateRow> rows_;
  std::uint64_t refused_ = 0;
  dds::Participant participant_;
  dds::Reader reader_;  // last: stops before what its callback uses goes
};

// Writes the rows as CSV (header robot_id,stamp_ns,estimator,name,value,sigma); throws
// std::runtime_error when the file cannot be written.
void write_estimator_state_csv(const std::string& path, const std::vector<EstimatorStateRow>& rows);

}  // namespace beaconloc
