#pragma once
// One input an estimator is pushed, whatever its kind: odometry, an identified or anonymous range,
// a laser scan, a raw time of flight (for the estimators that estimate the speed of sound
// themselves), or a pulse arrival with no firing time (seed 002). The out-of-sequence fusion, the offline stack and the benchmarks hold
// and replay inputs of this one type; Estimator::push is the one place that dispatches on it.
#include <variant>

#include "beaconloc/core/measurements.hpp"

namespace beaconloc {

using EstimatorInput =
    std::variant<OdometrySample, RangeMeasurement, LaserScanSample, RawTofSample, PulseArrivalSample>;

// The stamp an input is ordered by: the odometry's, the range's and the pulse arrival's (the
// pulse's arrival), the scan's, and for a raw time of flight the firing stamp (the arrival is the
// estimator's to work out: it needs the speed of sound, seed 002 eq. 21).
inline StampNs stamp_of(const EstimatorInput& input) {
  return std::visit(
      [](const auto& in) -> StampNs {
        using T = std::decay_t<decltype(in)>;
        if constexpr (std::is_same_v<T, RawTofSample>) {
          return in.fire_stamp_ns;
        } else {
          return in.stamp_ns;
        }
      },
      input);
}

inline bool is_odometry(const EstimatorInput& input) { return std::holds_alternative<OdometrySample>(input); }

// The name of the input's kind, the prefix its rejections are counted under in the localizer's
// Diagnostics ("odometry.", "range.", "laser.", "raw_tof.", "pulse.").
const char* kind_name(const EstimatorInput& input);

}  // namespace beaconloc
