// Seed 001's estimator pieces: the laser model against a hand-made grid, the association of
// Table 2, the map file, and the estimator's refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/occupancy_grid_io.hpp"
#include "exact_ranges.hpp"
#include "ukf_lrf/beacon_association.hpp"
#include "beaconloc/core/models/laser_beam_model.hpp"

namespace beaconloc::ukf_lrf {
namespace {

// A 4 m x 3 m room of 10 cm cells, walls on the border cells.
OccupancyGrid room() {
  OccupancyGrid grid({0.0, 0.0}, 0.1, 40, 30);
  grid.fill_border();
  return grid;
}

TEST(LaserModel, ExpectedRangesAreExactToTheCellFace) {
  const OccupancyGrid grid = room();  // inner faces at x = 0.1, 3.9 and y = 0.1, 2.9
  LaserBeams beams;
  for (double a : {-M_PI / 2, 0.0, M_PI / 2, M_PI}) beams.add_beam(a);
  beams.max_range_m = 80.0;
  double r[4];
  expected_laser_ranges(grid, Pose2(1.05, 1.25, 0.0), beams, r);
  EXPECT_NEAR(r[0], 1.15, 1e-9);  // down to y = 0.1
  EXPECT_NEAR(r[1], 2.85, 1e-9);  // ahead to x = 3.9
  EXPECT_NEAR(r[2], 1.65, 1e-9);  // up to y = 2.9
  EXPECT_NEAR(r[3], 0.95, 1e-9);  // behind to x = 0.1
  // The robot turned by 90 degrees and a scanner mounted 0.2 m ahead of its centre.
  beams.mount_base = Pose2(0.2, 0.0, 0.0);
  expected_laser_ranges(grid, Pose2(1.05, 1.25, M_PI / 2), beams, r);
  EXPECT_NEAR(r[1], 1.45, 1e-9);  // from y = 1.45 up to 2.9
  EXPECT_NEAR(r[0], 2.85, 1e-9);  // to the right: +x, to x = 3.9
  // Nothing within range reads the maximum range.
  OccupancyGrid empty({0.0, 0.0}, 0.1, 40, 30);
  beams.max_range_m = 5.0;
  expected_laser_ranges(empty, Pose2(1.05, 1.25, 0.0), beams, r);
  EXPECT_EQ(r[1], 5.0);
}

// The laser model casts a ray per beam per sigma point: from a pose far off the map (a diverged
// estimate, a robot placed by a typo) every beam still ends at once and reads what it meets or the
// maximum range (ray casting walks at most width + height cells; issue 23, item 3).
TEST(LaserModel, APoseFarOffTheMapReadsFiniteRangesAtOnce) {
  const OccupancyGrid grid = room();
  LaserBeams beams;
  for (int k = 0; k < 181; ++k) beams.add_beam((k - 90) * M_PI / 180.0);
  beams.max_range_m = 1e300;
  std::vector<double> r(beams.size());
  for (const Pose2& pose : {Pose2(-1e12, 1.5, 0.0), Pose2(1e300, -1e300, 2.0), Pose2(1e9, 1e9, -2.4)}) {
    expected_laser_ranges(grid, pose, beams, r.data());
    for (double range : r) EXPECT_TRUE(std::isfinite(range) && range > 0.0);
  }
  expected_laser_ranges(grid, Pose2(-1e12, 1.5, 0.0), beams, r.data());
  EXPECT_NEAR(r[90], 1e12, 1e-3);  // straight ahead: the room's west wall, 1e12 m away
}

TEST(BeaconAssociation, PicksTheBeaconWhosePredictedRangeExplainsTheMeasurement) {
  const std::vector<PredictedBeaconRange> beacons = {
      {1, 3.0, 0.2}, {2, 6.0, 0.2}, {3, 9.0, 0.2}, {4, 12.0, 0.2}};
  EXPECT_EQ(most_likely_beacon(3.3, beacons), 1u);
  EXPECT_EQ(most_likely_beacon(5.6, beacons), 2u);
  EXPECT_EQ(most_likely_beacon(9.4, beacons), 3u);
  EXPECT_EQ(most_likely_beacon(40.0, beacons), 4u);  // far from all: still the likeliest, no underflow
  // Maximum likelihood, not nearest mean: a wide prediction can win at equal distance.
  EXPECT_EQ(most_likely_beacon(5.0, {{1, 4.0, 0.01}, {2, 6.0, 4.0}}), 2u);
  EXPECT_FALSE(most_likely_beacon(5.0, {}));
}

TEST(OccupancyGridFile, RoundTripsAndRefusesMalformedFiles) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc_map_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  OccupancyGrid grid({-1.5, 2.0}, 0.05, 30, 20);
  grid.fill_border();
  grid.set_occupied(7, 3, true);
  write_occupancy_grid(grid, (dir / "map.yaml").string());
  const OccupancyGrid back = load_occupancy_grid((dir / "map.yaml").string());
  ASSERT_EQ(back.width(), 30);
  ASSERT_EQ(back.height(), 20);
  EXPECT_EQ(back.resolution_m(), 0.05);
  EXPECT_EQ(back.origin_m(), Eigen::Vector2d(-1.5, 2.0));
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 30; ++x) EXPECT_EQ(back.occupied(x, y), grid.occupied(x, y)) << x << ", " << y;
  }
  // A text PGM as ROS tools may write it; its top row is the map's largest y.
  std::ofstream(dir / "text.pgm") << "P2\n# comment\n3 2\n255\n0 254 254\n254 254 0\n";
  std::ofstream(dir / "text.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.0]\n";
  const OccupancyGrid text = load_occupancy_grid((dir / "text.yaml").string());
  EXPECT_TRUE(text.occupied(0, 1));
  EXPECT_TRUE(text.occupied(2, 0));
  EXPECT_FALSE(text.occupied(1, 0));
  // Malformed: each refused with a message naming the file.
  std::ofstream(dir / "rotated.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.5]\n";
  std::ofstream(dir / "no_image.yaml") << "resolution: 1.0\norigin: [0.0, 0.0, 0.0]\n";
  std::ofstream(dir / "short.pgm") << "P5\n10 10\n255\nabc";
  std::ofstream(dir / "short.yaml") << "image: short.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "bad_resolution.yaml") << "image: text.pgm\nresolution: -1\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "word_origin.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [a, 0, 0]\n";
  std::ofstream(dir / "threshold.yaml")
      << "image: text.pgm\nresolution: 1.0\norigin: [0, 0, 0]\noccupied_thresh: 7\n";
  std::ofstream(dir / "scale.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [0, 0, 0]\nmode: scale\n";
  std::ofstream(dir / "huge.pgm") << "P5\n100000 100000\n255\nabc";
  std::ofstream(dir / "huge.yaml") << "image: huge.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "bright.pgm") << "P5\n2 1\n100\n" << static_cast<char>(50) << static_cast<char>(200);
  std::ofstream(dir / "bright.yaml") << "image: bright.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "negate_true.yaml")
      << "image: text.pgm\nresolution: 1.0\norigin: [0, 0, 0]\nnegate: true\n";
  EXPECT_TRUE(load_occupancy_grid((dir / "negate_true.yaml").string()).occupied(1, 0));  // negated
  for (const char* name :
       {"rotated.yaml", "no_image.yaml", "short.yaml", "bad_resolution.yaml", "missing.yaml",
        "word_origin.yaml", "threshold.yaml", "scale.yaml", "huge.yaml", "bright.yaml"}) {
    EXPECT_THROW(load_occupancy_grid((dir / name).string()), MapFileError) << name;
  }
  std::filesystem::remove_all(dir);
}

TEST(UkfLrfEstimator, IsRegisteredInItsThreeModesAndRefusesWhatItCannotUse) {
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  // The laser modes need the map.
  EXPECT_THROW(EstimatorRegistry::instance().create("ukf_lrf", config), std::invalid_argument);
  auto beacons_only = EstimatorRegistry::instance().create("ukf_lrf_beacons_only", config);
  EXPECT_FALSE(beacons_only->uses_laser());
  config.occupancy_grid = std::make_shared<const OccupancyGrid>(room());
  auto fusion = EstimatorRegistry::instance().create("ukf_lrf", config);
  EXPECT_TRUE(fusion->uses_laser());
  EXPECT_EQ(EstimatorRegistry::instance().create("ukf_lrf_laser_only", config)->name(), "ukf_lrf_laser_only");

  // Placed by hand: without an initial pose, no estimate, and odometry refused with a reason.
  OdometrySample o;
  o.wheel_base_m = 0.4;
  EXPECT_EQ(fusion->predict(o).rejection, Rejection::kNoInitialPose);
  EXPECT_FALSE(fusion->estimate());

  config.initial_pose = Pose2(1.0, 1.0, 0.0);
  auto placed = EstimatorRegistry::instance().create("ukf_lrf", config);
  LaserScanSample bad;
  EXPECT_EQ(placed->update_laser(bad).rejection, Rejection::kMalformedScan);  // no beams
  // A range's numbers are checked as every estimator checks them (check_range_numbers).
  RangeMeasurement bad_range;
  bad_range.variance_m2 = 1e-2;
  bad_range.range_m = std::nan("");
  EXPECT_EQ(placed->update(bad_range).rejection, Rejection::kNonFiniteRange);
  bad_range.range_m = 1e300;
  EXPECT_EQ(placed->update(bad_range).rejection, Rejection::kImplausibleRange);
  bad_range.range_m = 3.0;
  bad_range.variance_m2 = 0.0;
  EXPECT_EQ(placed->update(bad_range).rejection, Rejection::kInvalidRange);
  bad_range.variance_m2 = 1e-2;
  bad_range.stamp_ns = -1;
  EXPECT_EQ(placed->update(bad_range).rejection, Rejection::kInvalidStamp);
  RangeMeasurement before_map;
  before_map.range_m = 3.0;
  before_map.variance_m2 = 1e-2;
  EXPECT_EQ(placed->update(before_map).rejection, Rejection::kNoBeaconMap);
  EXPECT_TRUE(placed->predict(o).accepted);
  ASSERT_TRUE(placed->estimate());
  EXPECT_EQ(placed->estimate()->pose_map_base, Pose2(1.0, 1.0, 0.0));
}

// A robot driving along a 4 m x 3 m room with two beacons far apart, fed exact scans and ranges:
// the filter's full iteration (motion, association, correction) runs.
class RoomDrive {
 public:
  explicit RoomDrive(const std::string& estimator) {
    EstimatorConfig config;
    receivers_.receivers_base_m = {{0.0, 0.0}};
    receivers_.receiver_height_m = 0.3;
    config.receivers = receivers_;
    config.occupancy_grid = std::make_shared<const OccupancyGrid>(room());
    config.initial_pose = truth_;
    ukf_ = EstimatorRegistry::instance().create(estimator, config);
    map_ = BeaconMap({{1, {0.5, 0.5, 2.5}}, {2, {3.5, 2.5, 2.5}}});
    ukf_->set_beacon_map(map_);
  }
  InputResult odometry(StampNs stamp_ns, double v_mps) {
    const double dt = static_cast<double>(stamp_ns - stamp_ns_) * 1e-9;
    truth_.x() += v_mps * dt;
    stamp_ns_ = stamp_ns;
    OdometrySample o;
    o.stamp_ns = stamp_ns;
    o.wheel_base_m = 0.4;
    o.wheel_velocity_right_mps = o.wheel_velocity_left_mps = v_mps;
    return ukf_->predict(o);
  }
  LaserScanSample scan(StampNs stamp_ns, int beams = 19) const {
    LaserScanSample s;
    s.stamp_ns = stamp_ns;
    s.angle_min_rad = static_cast<float>(-M_PI / 2);
    s.angle_increment_rad = static_cast<float>(M_PI / (beams - 1));
    s.range_max_m = 30.0f;
    LaserBeams b;
    for (int i = 0; i < beams; ++i)
      b.add_beam(s.angle_min_rad + i * static_cast<double>(s.angle_increment_rad));
    std::vector<double> r(static_cast<std::size_t>(beams));
    expected_laser_ranges(room(), truth_, b, r.data());
    for (double x : r) s.ranges_m.push_back(static_cast<float>(x));
    return s;
  }
  RangeMeasurement range(StampNs stamp_ns, std::uint32_t beacon_id) const {
    RangeMeasurement r =
        test_support::exact_ranges(truth_, receivers_, *map_.find(beacon_id), stamp_ns, 0.16).front();
    r.beacon_id = kBeaconUnidentified;  // anonymous
    return r;
  }
  std::unique_ptr<Estimator> ukf_;
  ReceiverArray receivers_;
  BeaconMap map_;
  Pose2 truth_{0.6, 1.5, 0.0};
  StampNs stamp_ns_ = 0;
};

TEST(UkfLrfEstimator, FusesScansAtTheirOwnStampAndAssociatesAnonymousRanges) {
  RoomDrive drive("ukf_lrf");
  ASSERT_TRUE(drive.odometry(0, 0.0).accepted);  // the time line's anchor
  StampNs t = 0;
  for (int k = 1; k <= 100; ++k) {
    t += 22'000'000;
    ASSERT_TRUE(drive.odometry(t, 0.4).accepted);
    // The scan of this instant arrives after its odometry: fused at once, the covariance shrinks.
    const double before = drive.ukf_->estimate()->covariance.trace();
    ASSERT_TRUE(drive.ukf_->update_laser(drive.scan(t)).accepted);
    EXPECT_LT(drive.ukf_->estimate()->covariance.trace(), before);
    if (k % 10 == 0) {
      ASSERT_TRUE(drive.ukf_->update(drive.range(t, k % 20 == 0 ? 1u : 2u)).accepted);
    }
  }
  const PoseEstimate e = *drive.ukf_->estimate();
  EXPECT_LT((e.pose_map_base.head<2>() - drive.truth_.head<2>()).norm(), 0.01);
  EXPECT_LT(std::abs(wrap_angle_rad(e.pose_map_base.z() - drive.truth_.z())), 0.01);
  // The anonymous ranges went to the right beacons (the two are 4.5 m apart).
  const auto associations = drive.ukf_->take_associations();
  ASSERT_EQ(associations.size(), 10u);
  for (std::size_t i = 0; i < associations.size(); ++i)
    EXPECT_EQ(associations[i].beacon_id, i % 2 == 0 ? 2u : 1u);
  EXPECT_TRUE(drive.ukf_->take_associations().empty());  // taken
}

TEST(UkfLrfEstimator, HoldsAScanAheadOfTheOdometryRefusesStaleAndThinsLongScans) {
  RoomDrive drive("ukf_lrf_laser_only");
  ASSERT_TRUE(drive.odometry(0, 0.0).accepted);
  ASSERT_TRUE(drive.odometry(22'000'000, 0.0).accepted);
  const double before = drive.ukf_->estimate()->covariance.trace();
  // Stamped after the filter's time: held, nothing fused yet.
  ASSERT_TRUE(drive.ukf_->update_laser(drive.scan(44'000'000)).accepted);
  EXPECT_EQ(drive.ukf_->estimate()->covariance.trace(), before);
  ASSERT_TRUE(drive.odometry(44'000'000, 0.0).accepted);  // reaches its stamp: fused with the motion
  EXPECT_LT(drive.ukf_->estimate()->covariance.trace(), before);
  // Older than max_measurement_age_s (0.1 s) behind the filter: refused.
  EXPECT_EQ(drive.ukf_->update_laser(drive.scan(-100'000'000)).rejection, Rejection::kStaleScan);
  // A 721-beam scan is thinned to the paper's 19 beams and still fuses.
  EXPECT_TRUE(drive.ukf_->update_laser(drive.scan(44'000'000, 721)).accepted);
  // Scans that cannot be used are refused by reason.
  LaserScanSample all_nan = drive.scan(44'000'000);
  for (auto& r : all_nan.ranges_m) r = std::nanf("");
  EXPECT_EQ(drive.ukf_->update_laser(all_nan).rejection, Rejection::kNoUsableBeams);
  LaserScanSample unbounded = drive.scan(44'000'000);
  unbounded.range_max_m = std::numeric_limits<float>::infinity();
  EXPECT_EQ(drive.ukf_->update_laser(unbounded).rejection, Rejection::kMalformedScan);
  LaserScanSample no_increment = drive.scan(44'000'000);
  no_increment.angle_increment_rad = 0.0f;
  EXPECT_EQ(drive.ukf_->update_laser(no_increment).rejection, Rejection::kMalformedScan);
}

// A person in front of the scanner: the beams that meet them read short of the map and are left
// out, the others fused; a scan whose every beam is so is refused by reason.
TEST(UkfLrfEstimator, LeavesOutBeamsShortOfTheMapAndRefusesAScanOfNothingElse) {
  RoomDrive drive("ukf_lrf_laser_only");
  ASSERT_TRUE(drive.odometry(0, 0.0).accepted);
  ASSERT_TRUE(drive.odometry(22'000'000, 0.0).accepted);
  const Pose2 before = drive.ukf_->estimate()->pose_map_base;
  const double trace_before = drive.ukf_->estimate()->covariance.trace();
  LaserScanSample person = drive.scan(22'000'000);
  for (std::size_t i = 7; i <= 11; ++i) person.ranges_m[i] = 0.6f;  // five beams ahead, 0.6 m: someone
  ASSERT_TRUE(drive.ukf_->update_laser(person).accepted);
  EXPECT_LT(drive.ukf_->estimate()->covariance.trace(), trace_before);  // the other 14 fused
  EXPECT_LT((drive.ukf_->estimate()->pose_map_base.head<2>() - before.head<2>()).norm(), 0.01);
  const auto gated = [&] {
    for (const Estimator::StateValue& v : drive.ukf_->state_values()) {
      if (v.name == "beams_gated") return v.value;
    }
    return -1.0;
  };
  EXPECT_EQ(gated(), 5.0);
  LaserScanSample crowd = drive.scan(22'000'000);
  for (float& r : crowd.ranges_m) r = 0.3f;  // everything a person: nothing the map explains
  EXPECT_EQ(drive.ukf_->update_laser(crowd).rejection, Rejection::kEveryComponentGated);
  EXPECT_EQ(gated(), 5.0 + 19.0);
  // Without the gate (beam_gate_sigma=0, the paper's eq. 16-21), the person's beams pull the pose.
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  config.occupancy_grid = std::make_shared<const OccupancyGrid>(room());
  config.initial_pose = drive.truth_;
  config.parameters = {{"beam_gate_sigma", 0.0}};
  auto ungated = EstimatorRegistry::instance().create("ukf_lrf_laser_only", config);
  OdometrySample o;
  o.wheel_base_m = 0.4;
  o.stamp_ns = 22'000'000;
  ASSERT_TRUE(ungated->predict(o).accepted);
  ASSERT_TRUE(ungated->update_laser(person).accepted);
  EXPECT_GT((ungated->estimate()->pose_map_base.head<2>() - before.head<2>()).norm(), 0.02);
}

TEST(UkfLrfEstimator, EveryPlaceableEstimatorRestartsFromAGivenPose) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  config.occupancy_grid = std::make_shared<const OccupancyGrid>(room());
  for (const char* name : {"ukf_lrf_beacons_only", "range_ekf", "duhl"}) {
    EstimatorConfig c = config;
    if (std::string(name) == "ukf_lrf_beacons_only") c.receivers.receivers_base_m = {{0.0, 0.0}};
    auto e = EstimatorRegistry::instance().create(name, c);
    OdometrySample o;
    o.wheel_base_m = 0.4;
    EXPECT_EQ(e->reset(0, Pose2(1.0, 2.0, std::nan("")), 0.01 * Cov3::Identity()).rejection,
              Rejection::kInvalidInitialPose)
        << name;
    Cov3 not_positive = Cov3::Identity();
    not_positive(2, 2) = -1.0;
    EXPECT_EQ(e->reset(0, Pose2(1.0, 2.0, 0.3), not_positive).rejection, Rejection::kInvalidInitialPose) << name;
    ASSERT_TRUE(e->reset(0, Pose2(1.0, 2.0, 0.3), 0.01 * Cov3::Identity()).accepted) << name;
    ASSERT_TRUE(e->predict(o).accepted) << name;
    ASSERT_TRUE(e->estimate()) << name;
    EXPECT_TRUE(e->estimate()->pose_map_base.isApprox(Pose2(1.0, 2.0, 0.3), 1e-12)) << name;
    EXPECT_EQ(e->estimate()->covariance, 0.01 * Cov3::Identity()) << name;
  }
}

TEST(UkfLrfEstimator, RefusesBadParametersAtStart) {
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  for (const auto& [name, value] : std::vector<std::pair<std::string, double>>{{"ut_alpha", 0.0},
                                                                               {"initial_sigma_xy_m", 0.0},
                                                                               {"alpha1", -0.01},
                                                                               {"beacon_sigma_m", 0.0},
                                                                               {"max_beams", 0.0},
                                                                               {"beam_gate_sigma", 0.5},
                                                                               {"beam_gate_sigma", -1.0},
                                                                               {"ut_kappa", -10.0}}) {
    config.parameters = {{name, value}};
    EXPECT_THROW(EstimatorRegistry::instance().create("ukf_lrf_beacons_only", config), std::invalid_argument)
        << name;
  }
}

}  // namespace
}  // namespace beaconloc::ukf_lrf
