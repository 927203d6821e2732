// Cost of one fused update of the seed 001 UKF (ukf_lrf) in the paper's setup: the 28-element
// augmented state (pose, two odometry noises, four beacon ranges, 19 laser beams), 57 sigma
// points, every one ray-cast for the 19 beams on the classroom's 10 cm grid; the prediction of
// eq. 9-13, the association of Table 2 and the correction of eq. 15-22. The paper: 8 ms per
// iteration (MATLAB, i7-3770 at 3.4 GHz, Sec. 4.1).
#include <benchmark/benchmark.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "sim/scenario_yaml.hpp"
#include "ukf_lrf/laser_model.hpp"

namespace beaconloc {
namespace {

void BM_UkfLrfFusedUpdate(benchmark::State& state) {
  const sim::Scenario scenario = sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) +
                                                         "/examples/scenarios/seed001_classroom.yaml");
  EstimatorConfig config;
  config.receivers = scenario.receivers;
  config.occupancy_grid = std::make_shared<const OccupancyGrid>(*scenario.map);
  const Pose2 pose = scenario.trajectory.pose_at(0.0);
  config.initial_pose = pose;
  auto ukf = EstimatorRegistry::instance().create("ukf_lrf", config);
  const BeaconMap map(scenario.beacons);
  ukf->set_beacon_map(map);

  LaserScanSample scan;
  scan.angle_min_rad = static_cast<float>(-M_PI / 2);
  scan.angle_increment_rad = static_cast<float>(M_PI / 18);
  scan.range_min_m = 0.0f;
  scan.range_max_m = 80.0f;
  ukf_lrf::LaserBeams beams;
  for (int i = 0; i < 19; ++i) beams.add_beam(scan.angle_min_rad + static_cast<float>(i) * scan.angle_increment_rad);
  double expected[19];
  ukf_lrf::expected_laser_ranges(*scenario.map, pose, beams, expected);
  for (double r : expected) scan.ranges_m.push_back(static_cast<float>(r));

  StampNs stamp_ns = 0;
  OdometrySample o;
  o.wheel_base_m = scenario.wheel_base_m;
  o.stamp_ns = stamp_ns;
  ukf->predict(o);  // the time line's anchor
  for (auto _ : state) {
    stamp_ns += 22'000'000;
    for (const Beacon& b : map.beacons()) {
      RangeMeasurement r;
      r.stamp_ns = stamp_ns;
      r.range_m = predict_range(pose, scenario.receivers.receivers_base_m[0],
                                scenario.receivers.receiver_height_m, b.position_map_m)
                      .range_m;
      r.variance_m2 = 0.16;
      ukf->update(r);
    }
    scan.stamp_ns = stamp_ns;
    ukf->update_laser(scan);
    o.stamp_ns = stamp_ns;
    if (!ukf->predict(o).accepted) throw std::logic_error("the fused update was refused");
  }
}
BENCHMARK(BM_UkfLrfFusedUpdate);

}  // namespace
}  // namespace beaconloc
