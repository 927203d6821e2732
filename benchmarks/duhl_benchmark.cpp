// Cost of the seed 000 DUHL estimator with ten Txs in its available set (trajectory 3 has ten):
//  - BM_DuhlOdometryStep: a 100 Hz step without a correction (eq. 14, 16, and eq. 23-24 for
//    every Tx);
//  - BM_DuhlStepWithCorrection: a 100 Hz step with the 5 Hz correction, as every twentieth step
//    runs it: a Tx heard by the three receivers (eq. 25-27), then at the odometry step the UHL on
//    all ten Txs, R of eq. 21 and the EKF update of eq. 17-20;
//  - BM_UhlSolveTenTxs: the UHL alone.
// The paper's Table III: 0.55-0.97 ms per step on a 2.66 GHz laptop, 0.97 ms for trajectory 3.
#include <benchmark/benchmark.h>

#include <stdexcept>

#include "beaconloc/core/models/range_model.hpp"
#include "duhl/duhl_estimator.hpp"
#include "exact_ranges.hpp"

namespace beaconloc {
namespace {

constexpr StampNs kOdometryPeriodNs = 10'000'000;

// A robot standing under a 5 x 2 grid of Txs at z_T = 1.887 m (seed 000 trajectory 3), every
// Tx's distances known, so that all ten stay available.
class TenTxRobot {
 public:
  TenTxRobot() : duhl_(config()) {
    std::vector<Beacon> beacons;
    for (std::uint32_t i = 0; i < 10; ++i) {
      beacons.push_back({i + 1, {1.2 * (i % 5), 1.8 * (i / 5), 1.887}});
    }
    map_ = BeaconMap(beacons);
    duhl_.set_beacon_map(map_);
    for (std::uint32_t id = 1; id <= 10; ++id) {
      hear(id);
      odometry_step();
    }
    if (duhl_.available_txs() != 10 || !duhl_.estimate()) throw std::logic_error("setup: ten Txs expected");
  }
  void odometry_step() {
    stamp_ns_ += kOdometryPeriodNs;
    OdometrySample o;
    o.stamp_ns = stamp_ns_;
    o.wheel_base_m = 0.33;
    duhl_.predict(o);
  }
  void hear(std::uint32_t beacon_id) {
    for (const RangeMeasurement& r :
         test_support::exact_ranges(truth_, receivers_, *map_.find(beacon_id), stamp_ns_)) {
      duhl_.update(r);
    }
  }
  std::size_t available_txs() const { return duhl_.available_txs(); }

 private:
  static EstimatorConfig config() {
    EstimatorConfig c;
    c.receivers = ReceiverArray::on_circle(0.19, 3);
    return c;
  }
  ReceiverArray receivers_ = ReceiverArray::on_circle(0.19, 3);
  duhl::Duhl duhl_;
  BeaconMap map_;
  Pose2 truth_{2.3, 0.8, 0.4};
  StampNs stamp_ns_ = 0;
};

void BM_DuhlOdometryStep(benchmark::State& state) {
  TenTxRobot robot;
  for (auto _ : state) robot.odometry_step();
  state.counters["txs"] = static_cast<double>(robot.available_txs());
}
BENCHMARK(BM_DuhlOdometryStep);

void BM_DuhlStepWithCorrection(benchmark::State& state) {
  TenTxRobot robot;
  std::uint32_t next = 1;
  for (auto _ : state) {
    robot.hear(next);
    robot.odometry_step();  // runs the UHL and the EKF correction
    next = next % 10 + 1;
  }
  state.counters["txs"] = static_cast<double>(robot.available_txs());
}
BENCHMARK(BM_DuhlStepWithCorrection);

// The UHL alone on the ten Txs (Table I: DM heading, IMR position).
void BM_UhlSolveTenTxs(benchmark::State& state) {
  std::vector<duhl::TxDistances> txs;
  const Pose2 truth(2.3, 0.8, 0.4);
  const ReceiverArray receivers = ReceiverArray::on_circle(0.19, 3);
  for (std::uint32_t i = 0; i < 10; ++i) {
    duhl::TxDistances t;
    t.tx_map_m = {1.2 * (i % 5), 1.8 * (i / 5), 1.887};
    for (int l = 0; l < 3; ++l)
      t.distances_m(l) = predict_range(truth, receivers.receivers_base_m[l], 0.0, t.tx_map_m).range_m;
    txs.push_back(t);
  }
  for (auto _ : state) benchmark::DoNotOptimize(duhl::solve_uhl(txs));
}
BENCHMARK(BM_UhlSolveTenTxs);

}  // namespace
}  // namespace beaconloc

BENCHMARK_MAIN();
