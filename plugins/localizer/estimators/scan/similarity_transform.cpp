#include "scan/similarity_transform.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace beaconloc::scan {
namespace {

// The two rows eq. 39 gives a local point: [x -y 1 0; y x 0 1], so that rows * T_C is eq. 44-45.
Eigen::Matrix<double, 2, 4> rows_of(const Eigen::Vector2d& local_m) {
  Eigen::Matrix<double, 2, 4> m;
  m << local_m.x(), -local_m.y(), 1.0, 0.0, local_m.y(), local_m.x(), 0.0, 1.0;
  return m;
}

bool finite(const PointPair& p) { return p.local_m.allFinite() && p.global_m.allFinite(); }

// Eq. 46 over the pairs.
template <class Pairs>
double mean_error_m(const Similarity2& s, const Pairs& pairs) {
  double sum = 0.0;
  for (const PointPair& p : pairs) sum += (s.apply(p.local_m) - p.global_m).norm();
  return pairs.empty() ? 0.0 : sum / static_cast<double>(pairs.size());
}

TransformFit failed(TransformFailure why) {
  TransformFit f;
  f.failure = why;
  return f;
}

// argmin sum w_i |rows_i T_C - g_i|^2 by its normal equations, factorization checked.
std::optional<Eigen::Vector4d> weighted_fit(const std::vector<PointPair>& pairs, const std::vector<double>& weights) {
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Matrix<double, 2, 4> m = rows_of(pairs[i].local_m);
    normal += weights[i] * m.transpose() * m;
    rhs += weights[i] * m.transpose() * pairs[i].global_m;
  }
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(normal);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.vectorD().array() > 1e-12 * normal.trace()).all()) {
    return std::nullopt;
  }
  const Eigen::Vector4d t = ldlt.solve(rhs);
  if (!t.allFinite()) return std::nullopt;
  return t;
}

}  // namespace

Eigen::Vector2d Similarity2::apply(const Eigen::Vector2d& local_m) const { return rows_of(local_m) * t_c; }

double Similarity2::rotation_rad() const { return std::atan2(t_c(1), t_c(0)); }

const char* to_string(TransformFailure failure) {
  switch (failure) {
    case TransformFailure::kNone: return "none";
    case TransformFailure::kTooFewPoints: return "too_few_points";
    case TransformFailure::kPointsTooClose: return "points_too_close";
    case TransformFailure::kSingular: return "singular";
    case TransformFailure::kNonFinite: return "non_finite";
    case TransformFailure::kImplausibleScale: return "implausible_scale";
  }
  return "unknown";
}

TransformFit analytic_similarity(const PointPair& newer, const PointPair& older, double min_separation_m) {
  if (!finite(newer) || !finite(older) || !std::isfinite(min_separation_m)) return failed(TransformFailure::kNonFinite);
  if ((newer.local_m - older.local_m).norm() < min_separation_m) return failed(TransformFailure::kPointsTooClose);
  Eigen::Matrix4d t_a;  // eq. 39
  t_a << rows_of(newer.local_m), rows_of(older.local_m);
  Eigen::Vector4d t_b;  // eq. 40
  t_b << newer.global_m, older.global_m;
  // det T_A = |p_k - p_k-t|^2: singular only where the two local points coincide.
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(t_a);
  if (!lu.isInvertible()) return failed(TransformFailure::kSingular);
  TransformFit fit;
  fit.transform = Similarity2{lu.solve(t_b)};  // eq. 41
  if (!fit.transform->t_c.allFinite()) return failed(TransformFailure::kNonFinite);
  fit.mean_error_m = mean_error_m(*fit.transform, std::vector<PointPair>{newer, older});
  return fit;
}

TransformFit numerical_similarity(const std::vector<PointPair>& pairs, const NumericalOptions& options) {
  if (pairs.size() < 2) return failed(TransformFailure::kTooFewPoints);
  for (const PointPair& p : pairs) {
    if (!finite(p)) return failed(TransformFailure::kNonFinite);
  }
  std::vector<double> weights(pairs.size(), 1.0);
  std::optional<Eigen::Vector4d> t = weighted_fit(pairs, weights);  // least squares: the start
  if (!t) return failed(TransformFailure::kSingular);
  TransformFit fit;
  fit.iterations = 1;  // the least-squares start
  while (fit.iterations < options.max_iterations) {
    const Similarity2 current{*t};
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      weights[i] = 1.0 / std::max((current.apply(pairs[i].local_m) - pairs[i].global_m).norm(), options.distance_floor_m);
    }
    const std::optional<Eigen::Vector4d> next = weighted_fit(pairs, weights);
    if (!next) break;  // keep the last good one
    ++fit.iterations;
    const double step = (*next - *t).norm();
    t = next;
    if (step < options.tolerance * std::max(1.0, t->norm())) {
      fit.converged = true;
      break;
    }
  }
  fit.transform = Similarity2{*t};
  fit.mean_error_m = mean_error_m(*fit.transform, pairs);
  return fit;
}

std::vector<PointPair> spread_points(const std::vector<PointPair>& track_newest_last, double min_separation_m,
                                     std::size_t max_points) {
  std::vector<PointPair> kept;
  for (auto it = track_newest_last.rbegin(); it != track_newest_last.rend() && kept.size() < max_points; ++it) {
    if (!finite(*it)) continue;
    bool apart = true;
    for (const PointPair& k : kept) apart = apart && (k.local_m - it->local_m).norm() > min_separation_m;
    if (apart) kept.push_back(*it);
  }
  return kept;
}

AnalyticAverage::AnalyticAverage(double min_separation_m) : min_separation_m_(min_separation_m) {
  if (!(std::isfinite(min_separation_m) && min_separation_m > 0.0)) {
    throw std::invalid_argument("AnalyticAverage: d_min must be a finite distance > 0");
  }
}

TransformFailure AnalyticAverage::add(const PointPair& pair) {
  if (!finite(pair)) return TransformFailure::kNonFinite;
  TransformFailure outcome = TransformFailure::kTooFewPoints;
  for (auto it = track_.rbegin(); it != track_.rend(); ++it) {
    if ((it->local_m - pair.local_m).norm() < min_separation_m_) continue;
    const TransformFit fit = analytic_similarity(pair, *it, min_separation_m_);
    outcome = fit.failure;
    if (fit.transform && !(std::abs(fit.transform->scale() - 1.0) <= kMaxVectorScaleError)) {
      outcome = TransformFailure::kImplausibleScale;
    } else if (fit.transform) {
      sum_ += fit.transform->t_c;
      ++count_;
    }
    break;
  }
  if (track_.empty() || (track_.back().local_m - pair.local_m).norm() >= kTrackSpacingM) {
    track_.push_back(pair);
    if (track_.size() > kMaxTrackPairs) track_.pop_front();
  }
  return outcome;
}

TransformFit AnalyticAverage::average() const {
  if (count_ == 0) return failed(TransformFailure::kTooFewPoints);
  TransformFit fit;
  fit.transform = Similarity2{sum_ / static_cast<double>(count_)};
  fit.mean_error_m = mean_error_m(*fit.transform, track_);
  return fit;
}

}  // namespace beaconloc::scan
