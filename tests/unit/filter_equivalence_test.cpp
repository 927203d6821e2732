// The filters of core/filters pinned to each other and to the textbook (issue 14):
//  - the iterated EKF with one iteration is the EKF, bit for bit;
//  - the UKF, the EKF, the IEKF and the H-infinity filter at theta = 0 are the textbook Kalman
//    filter on a linear model, and so is the UKF that corrects with the sigma points its
//    prediction drew (seed 001 Table 1), which refuses points drawn for another belief;
//  - the H-infinity filter tends to the EKF as its bound is relaxed (theta -> 0);
//  - the IEKF on a static range-only problem converges to the Gauss-Newton solution
//    (core/solvers/range_pose_solver);
//  - every failure is an outcome that leaves the state and covariance as they were;
//  - the UKF's component gate fuses the other components exactly as if the gated one had not
//    been measured.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/filters/h_infinity.hpp"
#include "beaconloc/core/filters/iterated_ekf.hpp"
#include "beaconloc/core/filters/ukf.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/linear_model.hpp"
#include "beaconloc/core/models/linear_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/models/stacked_model.hpp"
#include "beaconloc/core/solvers/range_pose_solver.hpp"

namespace beaconloc {
namespace {

Mat<3, 3> prior_covariance() {
  Mat<3, 3> p;
  p << 0.5, 0.1, 0.02, 0.1, 0.3, 0.05, 0.02, 0.05, 0.2;
  return p;
}

TEST(FilterEquivalence, TheIteratedEkfWithOneIterationIsTheEkfBitForBit) {
  Ekf<3> ekf(pose_space());
  IteratedEkf<3> iekf(pose_space(), {1, 0.0});
  const Vec<3> x0(1.0, 2.0, 3.1);
  ekf.reset(x0, prior_covariance());
  iekf.reset(x0, prior_covariance());
  const DiffDriveMotion motion(0.4, 1e-4 * Eigen::Matrix2d::Identity());
  for (int k = 0; k < 50; ++k) {
    ekf.predict(motion, Eigen::Vector2d(0.3, 0.5), 0.1);
    iekf.predict(motion, Eigen::Vector2d(0.3, 0.5), 0.1);
    const RangeModel model({0.19, 0.0}, 0.0, {k % 2 ? 3.0 : -1.0, k % 3 ? 4.0 : 0.0, 2.5}, 1e-3);
    const auto a = ekf.update(model, Vec<1>(3.0 + 0.01 * k));
    const auto b = iekf.update(model, Vec<1>(3.0 + 0.01 * k));
    ASSERT_EQ(a.outcome, b.outcome);
    ASSERT_EQ(a.nis, b.nis);
    ASSERT_EQ(ekf.state(), iekf.state()) << k;
    ASSERT_EQ(ekf.covariance(), iekf.covariance()) << k;
  }
}

// The textbook Kalman filter: x = F x + B u, P = F P F^T + B U B^T + Q; K = P H^T S^-1,
// x = x + K (z - H x), P = (I - K H) P.
struct Textbook {
  Vec<4> x;
  Mat<4, 4> p;
  void predict(const Mat<4, 4>& f, const Mat<4, 2>& b, const Vec<2>& u, const Mat<2, 2>& uc, const Mat<4, 4>& q) {
    x = f * x + b * u;
    p = f * p * f.transpose() + b * uc * b.transpose() + q;
  }
  void update(const Mat<2, 4>& h, const Mat<2, 2>& r, const Vec<2>& z) {
    const Mat<2, 2> s = h * p * h.transpose() + r;
    const Mat<4, 2> k = p * h.transpose() * s.inverse();
    x = x + k * (z - h * x);
    p = (Mat<4, 4>::Identity() - k * h) * p;
  }
};

// The UKF as seed 001 Table 1 runs it: one draw per iteration, the update correcting with the
// sigma points its prediction drew (R = r drawn in).
class OneDrawUkf {
 public:
  explicit OneDrawUkf(Eigen::MatrixXd r) : r_(std::move(r)) {}
  FilterOutcome reset(const Vec<4>& x, const Mat<4, 4>& p) { return ukf_.reset(x, p); }
  template <class Motion>
  PredictResult predict(const Motion& motion, const typename Motion::Input& u, double dt_s) {
    Ukf<4>::Predicted predicted = ukf_.predict(motion, u, dt_s, r_);
    points_ = std::move(predicted.points);
    return predicted.result;
  }
  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z) {
    if (!points_) return {FilterOutcome::kStaleSigmaPoints};
    return ukf_.update(*points_, model, z);
  }
  const Vec<4>& state() const { return ukf_.state(); }
  const Mat<4, 4>& covariance() const { return ukf_.covariance(); }

 private:
  Ukf<4> ukf_;
  Eigen::MatrixXd r_;
  std::optional<SigmaPoints<4>> points_;
};

// A linear motion whose noise is all on its input (Q = 0), as seed 001's: the UKF's prediction
// then keeps the points it moved for the update instead of drawing again.
struct InputNoiseOnly : LinearMotion<4, 2> {
  static constexpr bool kHasStateNoise = false;
  using LinearMotion<4, 2>::LinearMotion;
};

Mat<2, 2> linear_model_noise() {
  Mat<2, 2> r;
  r << 0.01, 0.002, 0.002, 0.02;
  return r;
}

template <class Filter, class Motion = LinearMotion<4, 2>>
void expect_textbook_on_linear_model(Filter filter, double tol) {
  // A constant-velocity model on [x, y, vx, vy] with an acceleration input, observed in position.
  const double dt = 0.1;
  Mat<4, 4> f = Mat<4, 4>::Identity();
  f(0, 2) = dt;
  f(1, 3) = dt;
  Mat<4, 2> b = Mat<4, 2>::Zero();
  b(0, 0) = b(1, 1) = 0.5 * dt * dt;
  b(2, 0) = b(3, 1) = dt;
  const Mat<2, 2> uc = 0.04 * Mat<2, 2>::Identity();
  const Mat<4, 4> q = (Motion::kHasStateNoise ? 1e-4 : 0.0) * Mat<4, 4>::Identity();
  Mat<2, 4> h = Mat<2, 4>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  h(0, 2) = 0.1;  // a little of the velocity in the first reading
  const Mat<2, 2> r = linear_model_noise();
  const Motion motion(f, b, uc, q);
  const LinearModel<2, 4> model(h, r);
  Textbook kf{Vec<4>(0.0, 1.0, 0.5, -0.2), Mat<4, 4>::Identity()};
  filter.reset(kf.x, kf.p);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int k = 0; k < 40; ++k) {
    const Vec<2> u(noise(rng), noise(rng));
    kf.predict(f, b, u, uc, q);
    ASSERT_TRUE(filter.predict(motion, u, dt).applied());
    ASSERT_TRUE(filter.state().isApprox(kf.x, tol)) << k << "\n" << filter.state() << "\n" << kf.x;
    ASSERT_TRUE(filter.covariance().isApprox(kf.p, tol)) << k;
    const Vec<2> z = h * kf.x + Vec<2>(noise(rng), noise(rng));
    const Mat<2, 2> s = h * kf.p * h.transpose() + r;  // the innovation's covariance, before the update
    kf.update(h, r, z);
    const UpdateResult updated = filter.update(model, z);
    ASSERT_TRUE(updated.applied());
    // The innovation's likelihood needs log det S (UpdateResult::log_det_s): the LDLT's here.
    EXPECT_NEAR(updated.log_det_s, std::log(s.determinant()), 10 * tol) << k;
    ASSERT_TRUE(filter.state().isApprox(kf.x, tol)) << k << "\n" << filter.state() << "\n" << kf.x;
    ASSERT_TRUE(filter.covariance().isApprox(kf.p, tol)) << k;
  }
}

TEST(FilterEquivalence, EveryFilterIsTheTextbookKalmanFilterOnALinearModel) {
  expect_textbook_on_linear_model(Ekf<4>(), 1e-9);
  expect_textbook_on_linear_model(IteratedEkf<4>(), 1e-9);
  expect_textbook_on_linear_model(HInfinityFilter<4>(StateSpace<4>(), 0.0), 1e-9);
  expect_textbook_on_linear_model(Ukf<4>(), 1e-9);
  UkfOptions augmented;
  augmented.augment_measurement_noise = true;
  expect_textbook_on_linear_model(Ukf<4>(StateSpace<4>(), augmented), 1e-9);
}

TEST(FilterEquivalence, TheUkfCorrectingWithThePointsItsPredictionDrewIsTheTextbookKalmanFilter) {
  // One draw over [x; w_u; v] per iteration (seed 001 Table 1) ...
  expect_textbook_on_linear_model<OneDrawUkf, InputNoiseOnly>(OneDrawUkf(linear_model_noise()), 1e-9);
  // ... and, with noise on the state (Q), the points drawn again from the prior.
  expect_textbook_on_linear_model(OneDrawUkf(linear_model_noise()), 1e-9);
}

TEST(FilterEquivalence, TheUkfRefusesSigmaPointsDrawnForAnotherBeliefOrAnotherNoise) {
  Ukf<3> ukf(pose_space());
  ukf.reset(Vec<3>(1.0, 2.0, 0.3), prior_covariance());
  const RangeModel model({0.19, 0.0}, 0.0, {3.0, 4.0, 2.5}, 1e-2);
  const std::optional<SigmaPoints<3>> points = ukf.sigma_points(model.noise());
  ASSERT_TRUE(points);
  const std::optional<SigmaPoints<3>> other_noise = ukf.sigma_points(Mat<1, 1>(2e-2));
  ASSERT_TRUE(other_noise);
  EXPECT_EQ(ukf.update(*other_noise, model, Vec<1>(3.4)).outcome, FilterOutcome::kStaleSigmaPoints);
  EXPECT_EQ(ukf.state(), Vec<3>(1.0, 2.0, 0.3));
  ASSERT_TRUE(ukf.update(*points, model, Vec<1>(3.4)).applied());
  const Vec<3> corrected = ukf.state();
  const Mat<3, 3> corrected_cov = ukf.covariance();
  // Used again after the belief moved: refused, nothing changed.
  EXPECT_EQ(ukf.update(*points, model, Vec<1>(3.4)).outcome, FilterOutcome::kStaleSigmaPoints);
  EXPECT_EQ(ukf.state(), corrected);
  EXPECT_EQ(ukf.covariance(), corrected_cov);
  // Points of another size (a 2-range R) against a 1-range model: refused, not an assertion.
  const std::optional<SigmaPoints<3>> two = ukf.sigma_points(Eigen::Matrix2d::Identity() * 1e-2);
  ASSERT_TRUE(two);
  EXPECT_EQ(ukf.update(*two, model, Vec<1>(3.4)).outcome, FilterOutcome::kStaleSigmaPoints);
}

TEST(FilterEquivalence, HInfinityTendsToTheEkfAsItsBoundIsRelaxed) {
  const Vec<3> x0(1.0, 2.0, 0.3);
  const RangeModel model({0.19, 0.0}, 0.0, {3.0, 4.0, 2.5}, 1e-2);
  const Vec<1> z(3.4);
  Ekf<3> ekf(pose_space());
  ekf.reset(x0, prior_covariance());
  ASSERT_TRUE(ekf.update(model, z).applied());
  double previous = std::numeric_limits<double>::infinity();
  for (double theta : {0.5, 0.1, 1e-2, 1e-3, 1e-4, 1e-6}) {
    HInfinityFilter<3> hinf(pose_space(), theta);
    hinf.reset(x0, prior_covariance());
    ASSERT_TRUE(hinf.update(model, z).applied()) << theta;
    const double gap = (hinf.state() - ekf.state()).norm() + (hinf.covariance() - ekf.covariance()).norm();
    EXPECT_LT(gap, previous) << theta;
    previous = gap;
    // A bound is paid for in covariance: the H-infinity covariance exceeds the EKF's.
    const Mat<3, 3> excess = hinf.covariance() - ekf.covariance();
    const Eigen::SelfAdjointEigenSolver<Mat<3, 3>> eig(excess);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << theta;
  }
  EXPECT_LT(previous, 1e-5);
  HInfinityFilter<3> exact(pose_space(), 0.0);
  exact.reset(x0, prior_covariance());
  ASSERT_TRUE(exact.update(model, z).applied());
  EXPECT_TRUE(exact.state().isApprox(ekf.state(), 1e-12));
  EXPECT_TRUE(exact.covariance().isApprox(ekf.covariance(), 1e-10));
}

TEST(FilterEquivalence, HInfinityRefusesABoundItCannotMeet) {
  HInfinityFilter<3> hinf(pose_space(), 100.0);  // theta above every eigenvalue of P^-1 + H^T R^-1 H
  hinf.reset(Vec<3>(1.0, 2.0, 0.3), prior_covariance());
  const auto result = hinf.update(RangeModel({0.19, 0.0}, 0.0, {3.0, 4.0, 2.5}, 1e-2), Vec<1>(3.4));
  EXPECT_EQ(result.outcome, FilterOutcome::kBoundNotMet);
  EXPECT_EQ(hinf.state(), Vec<3>(1.0, 2.0, 0.3));
  EXPECT_EQ(hinf.covariance(), prior_covariance());
}

TEST(FilterEquivalence, TheIteratedEkfOnAStaticRangeProblemConvergesToGaussNewton) {
  // Two receivers on the robot, six ceiling beacons, exact ranges plus a little noise.
  const Pose2 truth(2.1, 1.4, 0.6);
  const std::vector<Eigen::Vector2d> receivers{{0.2, 0.0}, {-0.2, 0.1}};
  const std::vector<Eigen::Vector3d> beacons{{0, 0, 3}, {5, 0, 3}, {5, 4, 3}, {0, 4, 3}, {2.5, 2, 3.2}, {1, 3, 2.9}};
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<RangeModel> models;
  std::vector<RangeObservation> observations;
  Eigen::VectorXd z(static_cast<Eigen::Index>(receivers.size() * beacons.size()));
  for (const auto& rx : receivers) {
    for (const auto& b : beacons) {
      const double range = predict_range(truth, rx, 0.0, b).range_m + noise(rng);
      z(static_cast<Eigen::Index>(models.size())) = range;
      models.emplace_back(rx, 0.0, b, 1e-4);
      observations.push_back({rx, 0.0, b, range, 1e-4});
    }
  }
  const RangePoseSolution gauss_newton = solve_pose_from_ranges(observations);
  ASSERT_TRUE(gauss_newton.ok) << gauss_newton.failure;

  // A diffuse prior 0.5 m and 0.3 rad off: the MAP estimate is the least-squares one (the prior
  // pulls it by ~1e-9 m; a far larger P only loses digits in the gain).
  IteratedEkf<3> iekf(pose_space(), {50, 1e-10});
  iekf.reset(Vec<3>(truth + Pose2(0.5, -0.4, 0.3)), 1e4 * Mat<3, 3>::Identity());
  const auto result = iekf.update(ModelList<RangeModel>(models), z);
  ASSERT_TRUE(result.applied()) << to_string(result.outcome);
  EXPECT_GT(result.iterations, 2);
  EXPECT_LT(result.iterations, 50);
  EXPECT_LT(pose_difference(iekf.state(), gauss_newton.pose).norm(), 1e-7)
      << iekf.state().transpose() << " vs " << gauss_newton.pose.transpose();
  EXPECT_TRUE(iekf.covariance().isApprox(gauss_newton.covariance, 1e-4));

  // The EKF, one linearization from the same prior, stops short of it.
  Ekf<3> ekf(pose_space());
  ekf.reset(Vec<3>(truth + Pose2(0.5, -0.4, 0.3)), 1e4 * Mat<3, 3>::Identity());
  ASSERT_TRUE(ekf.update(ModelList<RangeModel>(models), z).applied());
  EXPECT_GT(pose_difference(ekf.state(), gauss_newton.pose).norm(), 1e-3);
}

TEST(FilterEquivalence, TheUkfAveragesHeadingsAcrossPi) {
  Ukf<3> ukf(pose_space());
  Mat<3, 3> p = Mat<3, 3>::Zero();
  p.diagonal() << 0.01, 0.01, 0.04;
  ukf.reset(Vec<3>(0.0, 0.0, M_PI - 0.01), p);
  ASSERT_TRUE(ukf.predict(DiffDriveMotion(0.4, 1e-4 * Eigen::Matrix2d::Identity()), Eigen::Vector2d(0.1, 0.1), 0.1)
                  .applied());
  EXPECT_GT(std::abs(ukf.state().z()), M_PI - 0.02);  // near +-pi, not averaged to 0
  EXPECT_NEAR(ukf.covariance()(2, 2), 0.04, 1e-3);
}

// Every failure leaves the belief as it was, for every filter.
template <class Filter>
void expect_failures_change_nothing(Filter filter) {
  const Vec<3> x0(1.0, 2.0, 0.3);
  filter.reset(x0, prior_covariance());
  const RangeModel good({0.0, 0.0}, 0.0, {3.0, 4.0, 2.5}, 1e-2);
  const auto unchanged = [&] { return filter.state() == x0 && filter.covariance() == prior_covariance(); };
  EXPECT_EQ(filter.update(good, Vec<1>(std::nan(""))).outcome, FilterOutcome::kNonFinite);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(filter.update(RangeModel({0.0, 0.0}, 0.0, {3.0, 4.0, 2.5}, std::nan("")), Vec<1>(3.0)).outcome,
            FilterOutcome::kNonFinite);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(filter.update(good, Vec<1>(1e3), 10.0).outcome, FilterOutcome::kGated);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(filter.update(ModelList<RangeModel>({good, good}), Eigen::VectorXd::Zero(3)).outcome,
            FilterOutcome::kSizeMismatch);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(filter.predict(DiffDriveMotion(0.4, Eigen::Matrix2d::Identity()), Eigen::Vector2d(std::nan(""), 0.0), 0.1)
                .outcome,
            FilterOutcome::kNonFinite);
  EXPECT_TRUE(unchanged());
  // An infinite input noise (the filter checks the result it would take, not each factor).
  EXPECT_EQ(filter
                .predict(DiffDriveMotion(0.4, std::numeric_limits<double>::infinity() * Eigen::Matrix2d::Identity()),
                         Eigen::Vector2d(0.1, 0.2), 0.1)
                .outcome,
            FilterOutcome::kNonFinite);
  EXPECT_TRUE(unchanged());
  EXPECT_EQ(filter.reset(Vec<3>(std::nan(""), 0.0, 0.0), prior_covariance()), FilterOutcome::kNonFinite);
  EXPECT_TRUE(unchanged());
}

TEST(FilterEquivalence, EveryFailureIsAnOutcomeThatChangesNothing) {
  expect_failures_change_nothing(Ekf<3>(pose_space()));
  expect_failures_change_nothing(IteratedEkf<3>(pose_space()));
  expect_failures_change_nothing(HInfinityFilter<3>(pose_space(), 0.01));
  expect_failures_change_nothing(Ukf<3>(pose_space()));
}

TEST(FilterEquivalence, ASingularInnovationIsRefused) {
  Ekf<3> ekf(pose_space());
  ekf.reset(Vec<3>::Zero(), Mat<3, 3>::Zero());
  const auto result = ekf.update(LinearModel<1, 3>(Mat<1, 3>(1.0, 0.0, 0.0), Mat<1, 1>(0.0)), Vec<1>(0.1));
  EXPECT_EQ(result.outcome, FilterOutcome::kSingularInnovation);
  Ukf<3> ukf(pose_space());
  ukf.reset(Vec<3>::Zero(), Mat<3, 3>::Zero());
  EXPECT_EQ(ukf.update(LinearModel<1, 3>(Mat<1, 3>(1.0, 0.0, 0.0), Mat<1, 1>(0.01)), Vec<1>(0.1)).outcome,
            FilterOutcome::kNotPositiveDefinite);
}

// The textbook Kalman correction of x, P with the rows `rows` of z = H x + v.
std::pair<Vec<3>, Mat<3, 3>> kalman_with_rows(const Vec<3>& x, const Mat<3, 3>& p, const Mat<3, 3>& h,
                                              const Mat<3, 3>& r, const Vec<3>& z, const std::vector<Eigen::Index>& rows) {
  const Eigen::MatrixXd hs = h(rows, Eigen::all), rs = r(rows, rows);
  const Eigen::VectorXd zs = z(rows);
  const Eigen::MatrixXd s = hs * p * hs.transpose() + rs;
  const Eigen::MatrixXd k = p * hs.transpose() * s.inverse();
  return {x + k * (zs - hs * x), p - k * s * k.transpose()};
}

TEST(FilterEquivalence, TheUkfComponentGateFusesTheOthersAsIfTheOutlierWereNotMeasured) {
  Mat<3, 3> h;
  h << 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0;
  const Mat<3, 3> r = Vec<3>(0.01, 0.02, 0.015).asDiagonal();
  const Vec<3> x0(1.0, 2.0, 0.3);
  const LinearModel<3, 3> model(h, r);
  // Rows 0 and 1 agree with the prior; row 2 reads 40 of its sigmas long (a beam short of an
  // unmapped obstacle, reversed).
  Vec<3> z = h * x0 + Vec<3>(0.05, -0.04, 0.0);
  z(2) += 40.0 * std::sqrt((h.row(2) * prior_covariance() * h.row(2).transpose())(0, 0) + r(2, 2));
  for (const bool augmented : {false, true}) {
    SCOPED_TRACE(augmented ? "noise augmented" : "noise additive");
    Ukf<3> ukf(StateSpace<3>(), UkfOptions{{}, augmented});
    ukf.reset(x0, prior_covariance());
    const std::optional<SigmaPoints<3>> points = ukf.sigma_points(r);
    ASSERT_TRUE(points);
    const UpdateResult result = ukf.update(*points, model, z, std::numeric_limits<double>::infinity(),
                                           ComponentGate{0, 3, 3.0});
    ASSERT_TRUE(result.applied());
    EXPECT_EQ(result.components_gated, 1);
    const auto [x, p] = kalman_with_rows(x0, prior_covariance(), h, r, z, {0, 1});
    EXPECT_TRUE(ukf.state().isApprox(x, 1e-9)) << ukf.state().transpose() << " vs " << x.transpose();
    EXPECT_TRUE(ukf.covariance().isApprox(p, 1e-9));
  }
  // A gate over rows 0-1 only leaves row 2 to the update: the full Kalman correction.
  Ukf<3> ukf{StateSpace<3>()};
  ukf.reset(x0, prior_covariance());
  std::optional<SigmaPoints<3>> points = ukf.sigma_points(r);
  ASSERT_TRUE(points);
  UpdateResult result =
      ukf.update(*points, model, z, std::numeric_limits<double>::infinity(), ComponentGate{0, 2, 3.0});
  ASSERT_TRUE(result.applied());
  EXPECT_EQ(result.components_gated, 0);
  EXPECT_TRUE(ukf.state().isApprox(kalman_with_rows(x0, prior_covariance(), h, r, z, {0, 1, 2}).first, 1e-9));
  // Every component gated: nothing to fuse, refused, nothing changed.
  ukf.reset(x0, prior_covariance());
  points = ukf.sigma_points(r);
  ASSERT_TRUE(points);
  result = ukf.update(*points, model, Vec<3>(z + Vec<3>::Constant(100.0)), std::numeric_limits<double>::infinity(),
                      ComponentGate{0, 3, 3.0});
  EXPECT_EQ(result.outcome, FilterOutcome::kEveryComponentGated);
  EXPECT_EQ(result.components_gated, 3);
  EXPECT_EQ(ukf.state(), x0);
  EXPECT_EQ(ukf.covariance(), prior_covariance());
  // A gate that is no number, or reaches past the measurement, is taken as it can be: NaN gates
  // nothing, the range is clamped to the components there are.
  for (const ComponentGate odd : {ComponentGate{0, 3, std::nan("")}, ComponentGate{0, 3, -1.0},
                                  ComponentGate{2, std::numeric_limits<Eigen::Index>::max(), 3.0},
                                  ComponentGate{std::numeric_limits<Eigen::Index>::max(), 5, 3.0}}) {
    ukf.reset(x0, prior_covariance());
    points = ukf.sigma_points(r);
    ASSERT_TRUE(points);
    result = ukf.update(*points, model, z, std::numeric_limits<double>::infinity(), odd);
    ASSERT_TRUE(result.applied());
    EXPECT_EQ(result.components_gated, odd.sigmas == 3.0 && odd.first == 2 ? 1 : 0);
  }
}

}  // namespace
}  // namespace beaconloc
