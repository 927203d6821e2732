#include "scan/inverse_trajectory.hpp"

#include <optional>

#include "scan/scan_estimator.hpp"

namespace beaconloc::scan {

std::vector<RecordedInput> reversed_inputs(const InputLog<RecordedInput>& log) {
  std::vector<RecordedInput> out;
  out.reserve(log.size());
  std::optional<StampNs> newest_ns;
  std::optional<OdometrySample> newer;  // the odometry sample after the one at hand
  log.newest_first([&](const RecordedInput& item) {
    const StampNs stamp_ns = std::visit([](const auto& x) { return x.stamp_ns; }, item);
    if (!newest_ns) newest_ns = stamp_ns;
    const StampNs mirrored_ns = *newest_ns - stamp_ns;
    if (const auto* range = std::get_if<RangeMeasurement>(&item)) {
      RangeMeasurement r = *range;
      r.stamp_ns = mirrored_ns;
      out.emplace_back(r);
      return;
    }
    const OdometrySample& o = std::get<OdometrySample>(item);
    OdometrySample backwards = o;
    backwards.stamp_ns = mirrored_ns;
    // The newest sample starts the backwards time line (no interval before it to move over).
    backwards.wheel_velocity_right_mps = newer ? -newer->wheel_velocity_right_mps : 0.0;
    backwards.wheel_velocity_left_mps = newer ? -newer->wheel_velocity_left_mps : 0.0;
    if (newer) backwards.wheel_velocity_covariance = newer->wheel_velocity_covariance;
    out.emplace_back(backwards);
    newer = o;
  });
  return out;
}

BeaconCalibration inverse_trajectory_calibration(const EstimatorConfig& config, const BeaconMap& map,
                                                 const InputLog<RecordedInput>& log) {
  EstimatorConfig backwards_config = config;
  backwards_config.parameters["inverse_trajectory"] = 0.0;  // the virtual drive makes no virtual drive
  ScanEstimator backwards(backwards_config);
  backwards.set_beacon_map(map);
  for (const RecordedInput& input : reversed_inputs(log)) {
    std::visit([&](const auto& x) { backwards.push(x); }, input);
  }
  backwards.finish();
  return backwards.calibration();
}

}  // namespace beaconloc::scan
