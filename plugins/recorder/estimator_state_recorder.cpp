#include "estimator_state_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

namespace beaconloc {

EstimatorStateRecorder::EstimatorStateRecorder(const dds::DdsOptions& dds)
    : participant_(dds, "beaconloc.estimator_state_recorder") {
  reader_ = participant_.subscribe<msg::EstimatorStatePubSubType>(dds::kEstimatorStateTopic, [this](const msg::EstimatorState& m) {
    std::vector<EstimatorStateRow> rows;
    for (const msg::EstimatorStateValue& v : m.values()) {
      if (!std::isfinite(v.value()) || !std::isfinite(v.sigma())) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++refused_;
        return;
      }
      rows.push_back({m.robot_id(), m.stamp_ns(), m.estimator(), {v.name(), v.value(), v.sigma()}});
    }
    std::lock_guard<std::mutex> lock(mutex_);
    rows_.insert(rows_.end(), rows.begin(), rows.end());
  });
}

std::vector<EstimatorStateRow> EstimatorStateRecorder::rows() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rows_;
}

std::uint64_t EstimatorStateRecorder::refused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return refused_;
}

void write_estimator_state_csv(const std::string& path, const std::vector<EstimatorStateRow>& rows) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  out.precision(12);
  out << "robot_id,stamp_ns,estimator,name,value,sigma\n";
  for (const EstimatorStateRow& r : rows) {
    out << r.robot_id << ',' << r.stamp_ns << ',' << r.estimator << ',' << r.value.name << ',' << r.value.value << ','
        << r.value.sigma << '\n';
  }
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace beaconloc
