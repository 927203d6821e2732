#include "range_calibration.hpp"

#include <cmath>
#include <string>

namespace beaconloc {

std::optional<RangeCalibrationIndex> RangeCalibrationStates::index(std::uint32_t beacon_id) const {
  if (!enabled()) return std::nullopt;
  const auto at = scale_at_.find(key(beacon_id));
  if (at == scale_at_.end()) return std::nullopt;
  return RangeCalibrationIndex{at->second, at->second + 1};
}

std::optional<RangeCalibrationIndex> RangeCalibrationStates::add(std::uint32_t beacon_id, State& x, Covariance& p) {
  if (const auto known = index(beacon_id)) return *known;
  if (!enabled()) return std::nullopt;
  if (scale_at_.size() >= kMaxPairs) {
    uncalibrated_.insert(beacon_id);
    return std::nullopt;
  }
  const Eigen::Index n = x.size();
  State grown = State::Zero(n + 2);
  grown.head(n) = x;
  grown(n) = 1.0;  // scale
  Covariance p_grown = Covariance::Zero(n + 2, n + 2);
  p_grown.topLeftCorner(n, n) = p;
  p_grown(n, n) = scale_sigma_ * scale_sigma_;
  p_grown(n + 1, n + 1) = bias_sigma_m_ * bias_sigma_m_;
  x = std::move(grown);
  p = std::move(p_grown);
  scale_at_[key(beacon_id)] = n;
  return RangeCalibrationIndex{n, n + 1};
}

bool RangeCalibrationStates::plausible(const State& x) const {
  for (const auto& [k, s] : scale_at_) {
    if (!(x(s) >= kMinScale && x(s) <= kMaxScale)) return false;
  }
  return true;
}

void RangeCalibrationStates::to_prior(State& x, Covariance& p, bool values) const {
  const Eigen::Index n = x.size() - kPoseSize;
  p.topRightCorner(kPoseSize, n).setZero();
  p.bottomLeftCorner(n, kPoseSize).setZero();
  p.bottomRightCorner(n, n).setZero();
  for (const auto& [k, s] : scale_at_) {
    p(s, s) = scale_sigma_ * scale_sigma_;
    p(s + 1, s + 1) = bias_sigma_m_ * bias_sigma_m_;
    if (values) {
      x(s) = 1.0;
      x(s + 1) = 0.0;
    }
  }
}

RangeCalibrationStates::Corrected RangeCalibrationStates::corrected(std::uint32_t beacon_id, double range_m,
                                                                    double variance_m2, const State& x) const {
  const auto at = index(beacon_id);
  if (!at) return {range_m, variance_m2};
  const double scale = x(*at->scale), bias = x(*at->bias_m);
  return {(range_m - bias) / scale, variance_m2 / (scale * scale)};
}

std::vector<Estimator::StateValue> RangeCalibrationStates::values(const State& x, const Covariance& p) const {
  std::vector<Estimator::StateValue> out;
  for (const auto& [k, s] : scale_at_) {
    const std::string suffix = mode_ == RangeCalibrationMode::kShared ? "" : "_b" + std::to_string(k);
    out.push_back({"range_scale" + suffix, x(s), std::sqrt(p(s, s))});
    out.push_back({"range_bias_m" + suffix, x(s + 1), std::sqrt(p(s + 1, s + 1))});
  }
  return out;
}

}  // namespace beaconloc
