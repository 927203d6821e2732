#include "beaconloc/core/models/range_noise_scale.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace beaconloc {

namespace {
constexpr double kMedianOfAbsoluteNormal = 0.6744897501960817;  // Phi^-1(0.75)
}  // namespace

RangeNoiseScale::RangeNoiseScale(double step, double min_scale, double max_scale)
    : step_(step), min_log_scale_(std::log(min_scale)), max_log_scale_(std::log(max_scale)) {
  if (!(step > 0.0 && step < 1.0) || !(min_scale > 0.0 && min_scale <= 1.0 && max_scale >= 1.0) ||
      !std::isfinite(max_scale)) {
    throw std::invalid_argument("RangeNoiseScale: step in (0, 1), 0 < min_scale <= 1 <= max_scale");
  }
}

double RangeNoiseScale::scale() const { return std::exp(log_scale_); }

void RangeNoiseScale::learn(double innovation_m, double state_m2, double declared_m2) {
  const double sigma_m = std::sqrt(state_m2 + variance_m2(declared_m2));
  const double z = std::abs(innovation_m) / sigma_m;
  if (!std::isfinite(z) || !(state_m2 >= 0.0) || !(declared_m2 > 0.0)) return;
  log_scale_ += step_ * ((z > kMedianOfAbsoluteNormal ? 1.0 : 0.0) - 0.5);
  log_scale_ = std::clamp(log_scale_, min_log_scale_, max_log_scale_);
  ++ranges_;
}

}  // namespace beaconloc
