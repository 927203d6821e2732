#pragma once
// Seed 003 (Gualda et al., SCAN) Sec. 3.5: the transform from a locally referenced ULPS's frame
// (LRULPS n) to the global one, found from points of the robot's track that both frames' filters
// estimated while the robot heard both groups. ERRATA: a 2D similarity, 4 parameters
// T_C = [T_C1, T_C2, T_C3, T_C4] = [a, b, tx, ty]:
//   x' = a x - b y + tx,  y' = b x + a y + ty                      (eq. 42-45)
// (a rotation by atan2(b, a) and a scale sqrt(a^2 + b^2), then a translation).
//  - analytic (Sec. 3.5.1): two local points at least d_min apart and their global twins,
//    T_C = T_A^-1 T_B (eq. 39-41), averaged over the overlap (T_C bar);
//  - numerical (Sec. 3.5.2): many points any two more than d_min apart, T_C minimizing the mean
//    distance between the transformed local points and the global ones (eq. 46-47). The paper
//    ran Matlab's fminunc; here iteratively reweighted least squares (each point weighted by the
//    inverse of its distance), which minimizes the same mean distance (not its square), started
//    from the closed-form least-squares fit.
// Pure maths: no clock, no DDS; every refusal a TransformFailure.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <deque>
#include <vector>

namespace beaconloc::scan {

struct Similarity2 {
  Eigen::Vector4d t_c = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // [a, b, tx, ty] (eq. 41)
  Eigen::Vector2d apply(const Eigen::Vector2d& local_m) const;    // eq. 42-45
  double scale() const { return t_c.head<2>().norm(); }
  double rotation_rad() const;
};

// One instant of the track as each frame's filter estimated it.
struct PointPair {
  Eigen::Vector2d local_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d global_m = Eigen::Vector2d::Zero();
};

enum class TransformFailure : std::uint8_t {
  kNone,
  kTooFewPoints,    // fewer than two pairs (numerical) or none apart by d_min yet (average)
  kPointsTooClose,  // the two local points closer than d_min (eq. 39 ill-conditioned)
  kSingular,        // the system's factorization failed (the points coincide)
  kNonFinite,       // a point or the result not finite
  kImplausibleScale,  // average: a vector whose scale is off 1 by more than kMaxVectorScaleError
};
const char* to_string(TransformFailure failure);

struct TransformFit {
  std::optional<Similarity2> transform;  // set when failure is kNone
  TransformFailure failure = TransformFailure::kNone;
  double mean_error_m = 0.0;  // eq. 46 over the pairs used
  int iterations = 0;         // numerical: reweighted solves
  bool converged = false;     // numerical: T_C stopped moving before max_iterations
};

// Eq. 39-41 from two pairs whose local points are at least min_separation_m (d_min) apart.
TransformFit analytic_similarity(const PointPair& newer, const PointPair& older, double min_separation_m);

struct NumericalOptions {
  int max_iterations = 100;
  double tolerance = 1e-10;       // stop when T_C moves less than this, relative to its norm (at least 1)
  double distance_floor_m = 1e-6;  // a weight's distance never below this (a point fitted exactly)
};
// Eq. 44-47 over every pair given (pick them with spread_points).
TransformFit numerical_similarity(const std::vector<PointPair>& pairs, const NumericalOptions& options = {});

// Sec. 3.5.2's point choice: walking the track newest first, a pair is kept when its local point is
// more than min_separation_m from every pair kept; at most max_points.
std::vector<PointPair> spread_points(const std::vector<PointPair>& track_newest_last, double min_separation_m,
                                     std::size_t max_points);

// Sec. 3.5.1's average over the overlap, T_C bar: each new pair is solved (eq. 41) with the
// newest earlier pair at least d_min away, and the vectors averaged. It keeps the overlap's
// track (a pair every kTrackSpacingM of local travel, the newest kMaxTrackPairs).
class AnalyticAverage {
 public:
  static constexpr double kTrackSpacingM = 0.01;
  // Not in the paper: a group's frame is in metres as the map is, so a vector's scale is 1 up to
  // the pairs' errors (a few cm over d_min, 1-2 %); one off by more than this comes from a pair
  // that is wrong (a fix an echo moved, a global pose that drifted), and one such vector in the
  // mean spoils the average (a scale of 0.08 from one pair was seen on seed 003 with 30 % echoes
  // in a trial build: the group was never calibrated). It is left out (kImplausibleScale).
  static constexpr double kMaxVectorScaleError = 0.1;
  static constexpr std::size_t kMaxTrackPairs = 10000;  // 100 m of overlap at kTrackSpacingM
  // Throws std::invalid_argument unless d_min is finite and > 0.
  explicit AnalyticAverage(double min_separation_m);
  // kNone when this pair added a vector to the average; why not otherwise.
  TransformFailure add(const PointPair& pair);
  std::size_t count() const { return count_; }
  // T_C bar, its mean error (eq. 46) over the overlap's track; kTooFewPoints before the first vector.
  TransformFit average() const;

 private:
  double min_separation_m_;
  std::deque<PointPair> track_;  // oldest first
  Eigen::Vector4d sum_ = Eigen::Vector4d::Zero();
  std::size_t count_ = 0;
};

}  // namespace beaconloc::scan
