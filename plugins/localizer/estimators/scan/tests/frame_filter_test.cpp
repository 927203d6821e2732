// Seed 003 Sec. 3.2-3.4 (scan/frame_filter.hpp, scan/frame_start.hpp): one frame's filter, EKF,
// UKF and H-infinity, on spherical and hyperbolic measurements, started from two Gauss-Newton
// fixes, on a drive under one group simulated here against its truth.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "scan/frame_filter.hpp"
#include "scan/frame_start.hpp"
#include "scan/group_fix.hpp"

namespace beaconloc::scan {
namespace {

constexpr double kWheelBaseM = 0.33;
constexpr double kOdometryPeriodS = 0.01;
constexpr double kSlotPeriodS = 0.02;  // one beacon a slot, a group of four every 80 ms (seed003_scan.yaml)
constexpr double kRangeSigmaM = 0.005;  // seed 003 Sec. 4
constexpr double kWheelSigmaMps = 0.02;
constexpr double kMaxRangeM = 6.103277808;  // a 5 m floor radius under a 3.5 m ceiling (Sec. 2)

// A LRULPS (Sec. 2): a square with a 1 m diagonal at 3.5 m, in its own frame.
std::vector<Eigen::Vector3d> square() {
  const double h = 0.353553390593;
  return {{h, h, 3.5}, {-h, h, 3.5}, {-h, -h, 3.5}, {h, -h, 3.5}};
}

struct RunFigures {
  bool started = false;
  double position_rms_m = 0.0;
  double heading_rms_rad = 0.0;
  double mean_nees = 0.0;  // 3 dof
  int applied = 0;
  int refused = 0;
};

// The robot drives through the group's coverage (0.4 m/s, a gentle left curve), its wheel speeds
// measured with noise at 100 Hz; each beacon in reach is heard in its slot.
RunFigures drive(FilterKind kind, Geometry geometry, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> wheel_noise(0.0, kWheelSigmaMps), range_noise(0.0, kRangeSigmaM);
  const std::vector<Eigen::Vector3d> beacons = square();
  FrameFilterSettings settings;
  settings.kind = kind;
  FrameFilter filter(settings);
  FrameStart start(FrameStartSettings{});
  bool started = false;
  Pose2 truth(-4.5, -1.0, 0.25);
  Pose2 odometry_pose = Pose2::Zero();
  const double v = 0.4, w = 0.03;
  std::vector<EpochRange> epoch;
  GroupMeasurements fix_in;
  fix_in.geometry = geometry;
  fix_in.range_sigma_m = kRangeSigmaM;
  RunFigures f;
  double sum_p2 = 0.0, sum_h2 = 0.0, sum_nees = 0.0;
  int scored = 0;
  const int steps = static_cast<int>(25.0 / kOdometryPeriodS);
  const int odometry_per_slot = static_cast<int>(std::lround(kSlotPeriodS / kOdometryPeriodS));
  for (int k = 1; k <= steps; ++k) {
    const double vr = v + w * kWheelBaseM / 2.0, vl = v - w * kWheelBaseM / 2.0;
    truth = predict_diff_drive(truth, vr, vl, kWheelBaseM, kOdometryPeriodS).pose;
    OdometrySample o;
    o.wheel_velocity_right_mps = vr + wheel_noise(rng);
    o.wheel_velocity_left_mps = vl + wheel_noise(rng);
    o.wheel_base_m = kWheelBaseM;
    o.wheel_velocity_covariance = Eigen::Matrix2d::Identity() * kWheelSigmaMps * kWheelSigmaMps;
    odometry_pose = predict_diff_drive(odometry_pose, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps,
                                       kWheelBaseM, kOdometryPeriodS)
                        .pose;
    EXPECT_TRUE(start.predict(o, kOdometryPeriodS, 0.0).applied());
    if (started) {
      EXPECT_TRUE(filter.predict(o, kOdometryPeriodS, 0.0).applied());
    }
    if (k % odometry_per_slot == 0) {
      const std::size_t b = static_cast<std::size_t>(k / odometry_per_slot) % beacons.size();
      const double range_m = (Eigen::Vector3d(truth.x(), truth.y(), 0.0) - beacons[b]).norm();
      if (b == 0) epoch.clear();
      if (range_m <= kMaxRangeM) {
        const double z = range_m + range_noise(rng);
        if (b == epoch.size()) epoch.push_back({beacons[b], z, odometry_pose});
        if (started && geometry == Geometry::kSpherical) {
          const UpdateResult u = filter.update_range(Eigen::Vector2d::Zero(), 0.0, beacons[b], z, kRangeSigmaM * kRangeSigmaM);
          (u.applied() ? f.applied : f.refused) += 1;
        }
      }
      if (b + 1 == beacons.size() && epoch.size() == beacons.size()) {  // a whole epoch: a fix, or a hyperbolic update
        if (!started) {
          fix_in.beacons_m.clear();
          fix_in.ranges_m.clear();
          for (const EpochRange& r : epoch) {
            fix_in.beacons_m.push_back(r.beacon_frame_m);
            fix_in.ranges_m.push_back(r.range_m);
          }
          if (const auto belief = start.add_fix(solve_group_fix(fix_in))) {
            EXPECT_EQ(filter.start(belief->pose_frame_base, belief->covariance), FilterOutcome::kApplied);
            started = true;
          }
        } else if (geometry == Geometry::kHyperbolic) {
          const UpdateResult u =
              filter.update_differences(Eigen::Vector2d::Zero(), 0.0, epoch, odometry_pose, kRangeSigmaM * kRangeSigmaM);
          (u.applied() ? f.applied : f.refused) += 1;
        }
      }
    }
    if (started) {
      const Pose2 e = pose_difference(filter.pose(), truth);
      sum_p2 += e.head<2>().squaredNorm();
      sum_h2 += e.z() * e.z();
      sum_nees += e.dot(filter.covariance().inverse() * e);
      ++scored;
    }
  }
  f.started = started;
  if (scored > 0) {
    f.position_rms_m = std::sqrt(sum_p2 / scored);
    f.heading_rms_rad = std::sqrt(sum_h2 / scored);
    f.mean_nees = sum_nees / scored;
  }
  return f;
}

TEST(FrameFilter, EveryFilterTracksTheRobotThroughAGroupInBothGeometries) {
  for (const Geometry geometry : {Geometry::kSpherical, Geometry::kHyperbolic}) {
    for (const FilterKind kind : {FilterKind::kEkf, FilterKind::kUkf, FilterKind::kHInfinity}) {
      double p = 0.0, h = 0.0, nees = 0.0;
      constexpr int kSeeds = 4;  // 4 seeds: 20 s under ASan
      for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
        const RunFigures f = drive(kind, geometry, seed);
        ASSERT_TRUE(f.started) << to_string(kind) << " seed " << seed;
        EXPECT_GT(f.applied, 100) << to_string(kind);
        p += f.position_rms_m / kSeeds;
        h += f.heading_rms_rad / kSeeds;
        nees += f.mean_nees / kSeeds;
      }
      std::printf("%s %s: position RMS %.4f m, heading RMS %.4f rad, mean NEES %.2f\n",
                  geometry == Geometry::kSpherical ? "spherical" : "hyperbolic", to_string(kind), p, h, nees);
      // Measured (these 4 seeds): 0.012 m / 0.021 rad spherical, 0.016 m / 0.033 rad hyperbolic,
      // the three filters within 1 mm of each other; mean NEES 4.1 for 3 dof: overconfident by a
      // third, mostly in the first seconds, while the heading from two fixes settles (an open
      // point: with 10 seeds it was 3.7).
      const double bound_m = geometry == Geometry::kSpherical ? 0.02 : 0.03;
      EXPECT_LT(p, bound_m) << to_string(kind);
      EXPECT_LT(h, 0.05) << to_string(kind);
      EXPECT_GT(nees, 1.5) << to_string(kind);
      EXPECT_LT(nees, 5.0) << to_string(kind);
    }
  }
}

// Two fixes and the odometry between them: the heading of a straight drive and of a curve, a
// covariance that covers the error, and a pair the odometry contradicts starts again.
TEST(FrameStart, TheHeadingComesFromTwoFixesAndTheOdometryBetweenThem) {
  for (const double w : {0.0, 0.25}) {
    FrameStart start(FrameStartSettings{});
    const Pose2 first(2.0, -1.0, 2.5);
    GroupFix fix;
    fix.position_m = first.head<2>();
    fix.covariance_m2 = Eigen::Matrix2d::Identity() * 1e-4;
    EXPECT_FALSE(start.add_fix(fix));
    EXPECT_EQ(start.waiting_for(), FrameStartWait::kTooShortBaseline);
    OdometrySample o;
    o.wheel_base_m = kWheelBaseM;
    o.wheel_velocity_right_mps = 0.4 + w * kWheelBaseM / 2.0;
    o.wheel_velocity_left_mps = 0.4 - w * kWheelBaseM / 2.0;
    o.wheel_velocity_covariance = Eigen::Matrix2d::Identity() * 1e-4;
    Pose2 truth = first;
    std::optional<FrameBelief> belief;
    for (int k = 0; k < 400 && !belief; ++k) {
      ASSERT_TRUE(start.predict(o, kOdometryPeriodS, 0.0).applied());
      truth = predict_diff_drive(truth, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, kWheelBaseM,
                                 kOdometryPeriodS)
                  .pose;
      if (k % 40 == 39) {  // a fix every 0.4 s
        fix.position_m = truth.head<2>();
        belief = start.add_fix(fix);
        if (!belief) {
          EXPECT_LT(start.displacement_m(), FrameStartSettings{}.heading_baseline_m);
        }
      }
    }
    ASSERT_TRUE(belief) << "w " << w;
    EXPECT_LT((belief->pose_frame_base.head<2>() - truth.head<2>()).norm(), 1e-9);
    EXPECT_NEAR(wrap_angle_rad(belief->pose_frame_base.z() - truth.z()), 0.0, 1e-9) << "w " << w;
    const double heading_sigma = std::sqrt(belief->covariance(2, 2));
    EXPECT_GT(heading_sigma, std::sqrt(2e-4) / 1.6);  // two fixes' 1 cm across a 1.2-1.6 m chord at least
    EXPECT_LT(heading_sigma, 0.05);
    EXPECT_EQ(belief->covariance, belief->covariance.transpose());
  }
  // A second fix 3 m from the first after 1.2 m of odometry: the first is dropped.
  FrameStart start(FrameStartSettings{});
  GroupFix fix;
  fix.covariance_m2 = Eigen::Matrix2d::Identity() * 1e-4;
  EXPECT_EQ(start.waiting_for(), FrameStartWait::kNoFix);
  EXPECT_FALSE(start.add_fix(fix));
  OdometrySample o;
  o.wheel_base_m = kWheelBaseM;
  o.wheel_velocity_right_mps = o.wheel_velocity_left_mps = 0.4;
  o.wheel_velocity_covariance = Eigen::Matrix2d::Identity() * 1e-4;
  for (int k = 0; k < 300; ++k) ASSERT_TRUE(start.predict(o, kOdometryPeriodS, 0.0).applied());
  fix.position_m = Eigen::Vector2d(3.0, 0.0);
  EXPECT_FALSE(start.add_fix(fix));
  EXPECT_EQ(start.displacement_m(), 0.0);  // started again from the newer fix
  GroupFix bad;
  bad.failure = GroupFixFailure::kResidualTooLarge;
  EXPECT_FALSE(start.add_fix(bad));
}

// Ranges taken along the way, moved to the end by the exact odometry from the exact end pose,
// are the ranges from the end pose.
TEST(FrameFilter, RangesMovedToTheEpochsEndAreTheRangesFromThere) {
  const std::vector<Eigen::Vector3d> beacons = square();
  const Pose2 end_frame(1.2, -0.7, 0.9);
  const Pose2 end_odometry(10.0, 4.0, -2.0);  // another origin: only differences count
  std::vector<EpochRange> ranges;
  for (std::size_t i = 0; i < beacons.size(); ++i) {
    const Pose2 back(-0.012 * static_cast<double>(3 - i), 0.001 * static_cast<double>(i), -0.01 * static_cast<double>(3 - i));
    const Pose2 then_frame = compose(end_frame, back);
    const double range_then = (Eigen::Vector3d(then_frame.x(), then_frame.y(), 0.0) - beacons[i]).norm();
    ranges.push_back({beacons[i], range_then, compose(end_odometry, back)});
  }
  const std::vector<double> at_end = ranges_at_end(end_frame, Eigen::Vector2d::Zero(), 0.0, ranges, end_odometry);
  for (std::size_t i = 0; i < beacons.size(); ++i) {
    const double truth = (Eigen::Vector3d(end_frame.x(), end_frame.y(), 0.0) - beacons[i]).norm();
    EXPECT_NEAR(at_end[i], truth, 1e-12) << i;
    if (i < 3) {
      EXPECT_GT(std::abs(ranges[i].range_m - truth), 1e-4) << "the test moves the robot";
    }
  }
}

}  // namespace
}  // namespace beaconloc::scan
