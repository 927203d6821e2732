// The measurement and motion models of core/models (issue 14): each analytic Jacobian against a
// numeric one (central differences composed in the state space), on states where the pose sits
// at other indices than [0, 1, 2] and with calibration states, and the models' noise.
#include <gtest/gtest.h>

#include <cmath>

#include "beaconloc/core/models/arrival_time_model.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/laser_beam_model.hpp"
#include "beaconloc/core/models/point_range_model.hpp"
#include "beaconloc/core/models/pose_observation_model.hpp"
#include "beaconloc/core/models/range_difference_model.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/models/stacked_model.hpp"
#include "beaconloc/core/models/velocity_motion.hpp"
#include "kleeman_iekf/slot_transition.hpp"

namespace beaconloc {
namespace {

constexpr double kStep = 1e-6;

// d residual(h(x (+) e_i d), h(x (-) e_i d)) / 2d, column by column.
template <class Model, int N>
Eigen::MatrixXd numeric_jacobian(const Model& model, const StateSpace<N>& space, const Vec<N>& x) {
  Eigen::MatrixXd j(model.size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Vec<N> e = Vec<N>::Zero(x.size());
    e(i) = kStep;
    const typename Model::Vector hi = model.predict(space.plus(x, e));
    const typename Model::Vector lo = model.predict(space.plus(x, Vec<N>(-e)));
    j.col(i) = model.residual(hi, lo) / (2.0 * kStep);
  }
  return j;
}

template <class Model, int N>
void expect_jacobian_matches(const Model& model, const StateSpace<N>& space, const Vec<N>& x, double tol) {
  const auto lin = model.linearize(x);
  EXPECT_TRUE(lin.predicted.isApprox(model.predict(x), 1e-15)) << "linearize and predict differ";
  const Eigen::MatrixXd numeric = numeric_jacobian(model, space, x);
  const Eigen::MatrixXd analytic = lin.jacobian;
  EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), tol) << "analytic\n" << analytic << "\nnumeric\n" << numeric;
}

TEST(RangeModel, JacobianMatchesNumericOnAPoseState) {
  const PoseSpace space = pose_space();
  const RangeModel model({0.19, 0.0}, 0.1, {2.0, 3.0, 2.5}, 1e-4);
  for (const Pose2& x : {Pose2(0.3, -0.4, 0.7), Pose2(4.0, 1.0, -2.9), Pose2(2.0, 3.0, M_PI)}) {
    expect_jacobian_matches(model, space, Vec<3>(x), 1e-8);
  }
  EXPECT_EQ(model.noise()(0, 0), 1e-4);
}

TEST(RangeModel, JacobianMatchesNumericWithThePoseElsewhereAndScaleAndBiasStates) {
  // [scale, v, x, bias, yaw, y]: the pose split around other states.
  const PoseIndex pose{2, 5, 4};
  const StateSpace<6> space = StateSpace<6>::with_pose(pose);
  const RangeModel model({0.1, -0.2}, 0.0, {1.0, 2.0, 2.8}, 1e-4, pose, RangeCalibrationIndex{0, 3});
  Vec<6> x;
  x << 1.02, 0.4, 3.0, 0.05, 1.2, -1.0;
  expect_jacobian_matches(model, space, x, 1e-8);
  // h = scale * d + bias.
  const double d = predict_range(Pose2(3.0, -1.0, 1.2), {0.1, -0.2}, 0.0, {1.0, 2.0, 2.8}).range_m;
  EXPECT_NEAR(model.predict(x)(0), 1.02 * d + 0.05, 1e-12);
}

TEST(RangeModel, DynamicStateGivesTheSameAsAFixedOne) {
  const RangeModel model({0.19, 0.0}, 0.1, {2.0, 3.0, 2.5}, 1e-4);
  const Vec<3> fixed(0.3, -0.4, 0.7);
  Eigen::VectorXd dynamic(5);
  dynamic << 0.3, -0.4, 0.7, 9.0, 9.0;  // pose first, two calibrated coordinates after
  const auto a = model.linearize(fixed);
  const auto b = model.linearize(dynamic);
  EXPECT_EQ(a.predicted(0), b.predicted(0));
  EXPECT_EQ(b.jacobian.cols(), 5);
  EXPECT_EQ(a.jacobian, b.jacobian.leftCols(3));
  EXPECT_EQ(b.jacobian.rightCols(2).norm(), 0.0);
}

TEST(PointRangeModel, JacobianMatchesNumericWithThePointAnywhereInTheState) {
  const StateSpace<2> plane;
  const PointRangeModel model(1.0, {2.0, 1.5, 5.4}, 1e-4);
  for (const Vec<2>& x : {Vec<2>(0.5, 0.5), Vec<2>(2.0, 1.5), Vec<2>(-3.0, 4.0)}) {
    expect_jacobian_matches(model, plane, x, 1e-8);
  }
  // [v, y, x]: the point at other indices; h is the 3D distance at the point's height.
  const StateSpace<3> three;
  const PointRangeModel elsewhere(1.0, {2.0, 1.5, 5.4}, 1e-4, PointIndex{2, 1});
  const Vec<3> x(7.0, 0.5, 0.3);
  expect_jacobian_matches(elsewhere, three, x, 1e-8);
  EXPECT_NEAR(elsewhere.predict(x)(0), std::sqrt(1.7 * 1.7 + 1.0 * 1.0 + 4.4 * 4.4), 1e-12);
  EXPECT_EQ(elsewhere.linearize(x).jacobian(0, 0), 0.0);
  EXPECT_EQ(model.noise()(0, 0), 1e-4);
  // Right under the beacon at its height: no gradient, and no NaN.
  const PointRangeModel at_beacon(5.4, {2.0, 1.5, 5.4}, 1e-4);
  EXPECT_TRUE(at_beacon.linearize(Vec<2>(2.0, 1.5)).jacobian.isZero());
}

TEST(RangeDifferenceModel, JacobianMatchesNumericAndNoiseIsEq19) {
  const PoseSpace space = pose_space();
  const RangeDifferenceModel model({0.0, 0.1}, 0.0, {{1.0, 1.0, 3.0}, {4.0, 1.0, 3.0}, {4.0, 5.0, 3.0}, {1.0, 5.0, 3.0}},
                                   0.01);
  ASSERT_EQ(model.size(), 3);
  expect_jacobian_matches(model, space, Vec<3>(2.0, 2.5, 0.4), 1e-8);
  const Eigen::MatrixXd r = model.noise();
  EXPECT_EQ(r(0, 0), 0.01);
  EXPECT_EQ(r(1, 1), 0.01);
  EXPECT_EQ(r(0, 2), 0.005);
  EXPECT_EQ(r(2, 1), 0.005);
  EXPECT_THROW(RangeDifferenceModel({0.0, 0.0}, 0.0, {{1.0, 1.0, 3.0}}, 0.01), std::invalid_argument);
}

TEST(ArrivalTimeModel, JacobianMatchesNumericOnSeed002State) {
  // [x, y, v, theta, T, t0, s] (seed 002 Sec. 3).
  const StateSpace<7> space({3});
  const ArrivalTimeModel model({3.0, 4.0, 2.4}, 0.3, 1e-8);
  Vec<7> x;
  x << 1.0, 2.0, 0.4, 0.6, 0.15, 10.0, 343.0;
  expect_jacobian_matches(model, space, x, 1e-7);
  // A robot at rest: t0 + d / s.
  x(2) = 0.0;
  const double d = Eigen::Vector3d(1.0 - 3.0, 2.0 - 4.0, 0.3 - 2.4).norm();
  EXPECT_NEAR(model.predict(x)(0), 10.0 + d / 343.0, 1e-15);
  // Moving towards the beacon (u points from the beacon to the robot): the pulse arrives sooner.
  x(2) = 1.0;
  x(3) = std::atan2(4.0 - 2.0, 3.0 - 1.0);
  EXPECT_LT(model.predict(x)(0), 10.0 + d / 343.0);
}

TEST(ArrivalTimeModel, AtRestTheGradientIsEquation23sUnitVectorOverTheSpeedOfSound) {
  // Eq. 23 at v = 0: d t / d x = u_x / s (its second term carries v). The rest of the gradient is
  // checked numerically above (ERRATA: derived, not printed).
  const ArrivalTimeModel model({3.0, 4.0, 0.0}, 0.0, 1e-8);
  Vec<7> x;
  x << 1.0, 2.0, 0.0, 0.3, 0.15, 0.0, 340.0;
  const double d = std::hypot(1.0 - 3.0, 2.0 - 4.0);
  const auto lin = model.linearize(x);
  EXPECT_NEAR(lin.jacobian(0, 0), (1.0 - 3.0) / d / 340.0, 1e-15);
  EXPECT_NEAR(lin.jacobian(0, 1), (2.0 - 4.0) / d / 340.0, 1e-15);
  EXPECT_EQ(lin.jacobian(0, 5), 1.0);
  EXPECT_EQ(lin.jacobian(0, 4), 0.0);  // T enters through the motion (eq. 15), not eq. 21
}

TEST(PoseObservationModel, JacobianIsTheSelectionAndTheResidualWrapsTheHeading) {
  const PoseIndex pose{1, 2, 0};
  const StateSpace<4> space = StateSpace<4>::with_pose(pose);
  const PoseObservationModel model(0.01 * Cov3::Identity(), pose);
  Vec<4> x(3.1, 1.0, 2.0, 7.0);
  expect_jacobian_matches(model, space, x, 1e-8);
  const Vec<3> r = model.residual(Vec<3>(1.0, 2.0, -3.1), model.predict(x));
  EXPECT_NEAR(r(2), 2.0 * M_PI - 6.2, 1e-12);  // -3.1 - 3.1 wrapped, not -6.2
}

TEST(LaserBeamModel, HasNoJacobianAndPredictsRayCasts) {
  static_assert(!LaserBeamModel::kHasJacobian, "a ray cast has no Jacobian: UKF only");
  auto grid = std::make_shared<OccupancyGrid>(Eigen::Vector2d(0.0, 0.0), 0.1, 40, 30);
  grid->fill_border();
  LaserBeams beams;
  beams.add_beam(0.0);
  beams.add_beam(M_PI / 2);
  const LaserBeamModel model(grid, beams, 0.01);
  const Eigen::VectorXd h = model.predict(Vec<3>(1.05, 1.25, 0.0));
  EXPECT_NEAR(h(0), 3.9 - 1.05, 1e-9);
  EXPECT_NEAR(h(1), 2.9 - 1.25, 1e-9);
  EXPECT_EQ(model.noise(), 0.01 * Eigen::MatrixXd::Identity(2, 2));
}

TEST(StackedModel, RangesAndAPoseObservationStackTheirHJacobianNoiseAndResiduals) {
  const PoseIndex pose{1, 2, 0};
  const StateSpace<4> space = StateSpace<4>::with_pose(pose);
  ModelList<RangeModel> ranges;
  ranges.add(RangeModel({0.19, 0.0}, 0.1, {2.0, 3.0, 2.5}, 1e-4, pose));
  ranges.add(RangeModel({-0.1, 0.2}, 0.1, {-1.0, 0.5, 2.7}, 4e-4, pose));
  Cov3 pose_cov;
  pose_cov << 0.01, 0.002, 0.0, 0.002, 0.02, 0.001, 0.0, 0.001, 0.03;
  const PoseObservationModel fix(pose_cov, pose);
  const StackedModel<ModelList<RangeModel>, PoseObservationModel> model(ranges, fix);
  ASSERT_EQ(model.size(), 5);
  const Vec<4> x(3.1, 1.0, 2.0, 7.0);  // [yaw, x, y, other]
  expect_jacobian_matches(model, space, x, 1e-8);
  const Eigen::VectorXd h = model.predict(x);
  EXPECT_EQ(h(0), ranges.parts()[0].predict(x)(0));
  EXPECT_EQ(h(1), ranges.parts()[1].predict(x)(0));
  EXPECT_EQ(Vec<3>(h.tail(3)), fix.predict(x));
  // R block-diagonal: the parts' own noises, nothing across them.
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(5, 5);
  r(0, 0) = 1e-4;
  r(1, 1) = 4e-4;
  r.bottomRightCorner(3, 3) = pose_cov;
  EXPECT_EQ(model.noise(), r);
  // Each part's residual: the heading's wraps, the ranges' do not.
  Eigen::VectorXd z = h;
  z(0) += 0.5;
  z(4) = -3.1;
  const Eigen::VectorXd res = model.residual(z, h);
  EXPECT_NEAR(res(0), 0.5, 1e-12);
  EXPECT_EQ(res(1), 0.0);
  EXPECT_NEAR(res(4), 2.0 * M_PI - 6.2, 1e-12);
}

TEST(MeasurementModels, OnlyModelsWithoutAnAngleSayTheirResidualIsThePlainDifference) {
  static_assert(plain_residual_v<RangeModel> && plain_residual_v<RangeDifferenceModel> &&
                    plain_residual_v<ArrivalTimeModel> && plain_residual_v<LaserBeamModel>,
                "");
  static_assert(!plain_residual_v<PoseObservationModel>, "its residual wraps the heading");
  static_assert(plain_residual_v<StackedModel<ModelList<RangeModel>, LaserBeamModel>>, "");
  static_assert(!plain_residual_v<StackedModel<ModelList<RangeModel>, PoseObservationModel>>, "");
  static_assert(!plain_residual_v<ModelList<PoseObservationModel>>, "");
  // And the one that says so computes it: z - h, whatever the numbers.
  const RangeModel range({0.0, 0.0}, 0.0, {1.0, 1.0, 2.5}, 0.16);
  EXPECT_EQ(range.residual(Vec<1>(-3.5), Vec<1>(3.5))(0), -7.0);
}

TEST(StackedModel, WithoutAJacobianInAPartTheStackHasNone) {
  static_assert(!StackedModel<ModelList<RangeModel>, LaserBeamModel>::kHasJacobian, "");
  static_assert(ModelList<RangeModel>::kHasJacobian, "");
  // An empty part (no beams: no grid needed, no ray cast) leaves the other as it is.
  ModelList<RangeModel> ranges({RangeModel({0.0, 0.0}, 0.0, {1.0, 1.0, 2.5}, 0.16)});
  const StackedModel<ModelList<RangeModel>, LaserBeamModel> model(ranges, LaserBeamModel(nullptr, LaserBeams{}, 0.01));
  EXPECT_EQ(model.size(), 1);
  EXPECT_EQ(model.predict(Vec<3>(0.0, 0.0, 0.0)), ranges.predict(Vec<3>(0.0, 0.0, 0.0)));
  EXPECT_EQ(model.noise(), Eigen::MatrixXd::Constant(1, 1, 0.16));
}

// noise_into (what the UKF builds R with, once per correction) writes what noise() gives: the
// laser's diagonal, and a stack of ranges and beams block-diagonal, the ranges through noise()
// (they have no noise_into), the beams in place.
TEST(StackedModel, ModelsThatWriteTheirNoiseInPlaceWriteWhatTheirNoiseGives) {
  static_assert(WritesNoiseInPlace<LaserBeamModel>::value && !WritesNoiseInPlace<RangeModel>::value, "");
  LaserBeams beams;
  for (int k = 0; k < 3; ++k) beams.add_beam(0.5 * k);
  const LaserBeamModel laser(nullptr, beams, 0.0025);
  Eigen::MatrixXd written = Eigen::MatrixXd::Zero(3, 3);
  noise_into(laser, written);
  EXPECT_EQ(written, laser.noise());
  ModelList<RangeModel> ranges({RangeModel({0.0, 0.0}, 0.0, {1.0, 1.0, 2.5}, 0.16),
                                RangeModel({0.0, 0.0}, 0.0, {2.0, 1.0, 2.5}, 0.09)});
  const StackedModel<ModelList<RangeModel>, LaserBeamModel> model(ranges, laser);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(5, 5);
  r.diagonal() << 0.16, 0.09, 0.0025, 0.0025, 0.0025;
  EXPECT_EQ(model.noise(), r);
}

// A motion model's F and G against central differences of x (+) dx(x, u).
// input_step: the difference step on the input (the arc's v / omega cancels digits for a small
// omega: on a straight line the step must carry omega well away from 0).
template <class Motion, int N>
void expect_motion_jacobians_match(const Motion& motion, const StateSpace<N>& space, const Vec<N>& x,
                                   const typename Motion::Input& u, double dt_s, double tol,
                                   double input_step = kStep) {
  const auto lin = motion.linearize(x, u, dt_s);
  EXPECT_TRUE(lin.step.isApprox(motion.step(x, u, dt_s), 1e-15));
  auto next = [&](const Vec<N>& xs, const typename Motion::Input& us) {
    return space.plus(xs, motion.step(xs, us, dt_s));
  };
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Vec<N> e = Vec<N>::Zero(x.size());
    e(i) = kStep;
    const Vec<N> col = space.minus(next(space.plus(x, e), u), next(space.plus(x, Vec<N>(-e)), u)) / (2 * kStep);
    EXPECT_LT((lin.jacobian_state.col(i) - col).cwiseAbs().maxCoeff(), tol) << "F column " << i;
  }
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    typename Motion::Input e = Motion::Input::Zero();
    e(i) = input_step;
    const Vec<N> col = space.minus(next(x, u + e), next(x, u - e)) / (2 * input_step);
    EXPECT_LT((lin.jacobian_input.col(i) - col).cwiseAbs().maxCoeff(), tol) << "G column " << i;
  }
}

TEST(DiffDriveMotion, JacobiansMatchNumericWithThePoseAnywhere) {
  expect_motion_jacobians_match(DiffDriveMotion(0.4, Eigen::Matrix2d::Identity()), pose_space(),
                                Vec<3>(1.0, 2.0, 3.0), Eigen::Vector2d(0.5, 0.3), 0.01, 1e-8);
  const PoseIndex pose{3, 0, 1};
  expect_motion_jacobians_match(DiffDriveMotion(0.4, Eigen::Matrix2d::Identity(), pose),
                                StateSpace<5>::with_pose(pose), Vec<5>(2.0, -3.0, 9.0, 1.0, 0.2),
                                Eigen::Vector2d(0.9, -0.3), 0.1, 1e-8);
}

TEST(VelocityMotion, JacobiansMatchNumericOnArcsAndStraightLines) {
  const VelocityMotion motion({0.02, 0.02, 0.02, 0.02});
  expect_motion_jacobians_match(motion, pose_space(), Vec<3>(1.0, 2.0, 3.0), Eigen::Vector2d(0.5, 0.4), 0.1,
                                1e-7);
  expect_motion_jacobians_match(motion, pose_space(), Vec<3>(1.0, 2.0, -0.5), Eigen::Vector2d(0.5, 0.0), 0.1,
                                1e-7, 1e-3);
  // Input noise: eq. 6 floored.
  EXPECT_EQ(motion.input_noise(Eigen::Vector2d(0.0, 0.0)), VelocityMotion::kMinVariance * Eigen::Matrix2d::Identity());
}

// Seed 002 eq. 15-16 (with the slot's mean heading, slot_transition.hpp) on its 7-number state.
TEST(KleemanSlotTransition, JacobiansMatchNumericAndAreEquation16WithoutATurn) {
  const kleeman::SlotTransition motion(1e-4, kleeman::SlotNoise{});
  Vec<7> x;
  x << 3.0, 4.0, 0.25, 2.5, 0.15, 12.0, 346.0;
  const StateSpace<7> space = kleeman::state_space();
  expect_motion_jacobians_match(motion, space, x, Vec<1>(0.07), 0.15, 1e-8);
  expect_motion_jacobians_match(motion, space, x, Vec<1>(0.0), 0.15, 1e-8);
  const auto lin = motion.linearize(x, Vec<1>(0.0), 0.15);
  Mat<7, 7> eq16 = Mat<7, 7>::Identity();
  const double v = 0.25, period = 0.15, c = std::cos(2.5), s = std::sin(2.5);
  eq16(0, 2) = period * c;
  eq16(0, 3) = -period * v * s;
  eq16(0, 4) = v * c;
  eq16(1, 2) = period * s;
  eq16(1, 3) = period * v * c;
  eq16(1, 4) = v * s;
  eq16(5, 4) = 1.0;
  EXPECT_TRUE(lin.jacobian_state.isApprox(eq16, 1e-15));
  EXPECT_DOUBLE_EQ(lin.step(5), period);  // t0(k+1) = t0(k) + T(k)
  // Travel by an unknown direction goes on x and y as noise.
  const Mat<7, 7> q = kleeman::SlotTransition(1e-4, kleeman::SlotNoise{}, 0.01).state_noise<7>(7, 0.15);
  EXPECT_DOUBLE_EQ(q(0, 0), kleeman::SlotNoise{}.position_m * kleeman::SlotNoise{}.position_m + 0.01);
}

}  // namespace
}  // namespace beaconloc
