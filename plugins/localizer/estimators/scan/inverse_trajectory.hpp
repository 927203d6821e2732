#pragma once
// Seed 003 Sec. 3.6, the inverse trajectory: "a new virtual trajectory of the MR starting from
// the final position (inside the GRULPS coverage area) and going backwards running the algorithm
// again if all the measurements were saved": the last LRULPSs of the drive are the first of the
// virtual one, next to a GRULPS, and are calibrated better there.
//
// The saved inputs are played newest first on a fresh estimator, on a time that runs backwards
// from the newest stamp (tau = t_newest - t): a range keeps its value at its mirrored stamp; an
// odometry sample at t_k, which moved the robot over (t_k-1, t_k], becomes one at tau_k that
// moves it over (tau_k+1, tau_k], the original (t_k, t_k+1]: the wheel speeds of the sample after
// it, negated (the robot drives its path backwards).
#include <variant>

#include "beaconloc/core/beacon_calibration.hpp"
#include "beaconloc/core/estimator.hpp"
#include "scan/input_log.hpp"

namespace beaconloc::scan {

using RecordedInput = std::variant<OdometrySample, RangeMeasurement>;

// The inputs as the backwards drive pushes them, oldest (of the virtual drive) first.
std::vector<RecordedInput> reversed_inputs(const InputLog<RecordedInput>& log);

// The calibration a scan estimator (configured as `config`, with no inverse pass of its own)
// finds on the backwards drive over `log`, with `map`.
BeaconCalibration inverse_trajectory_calibration(const EstimatorConfig& config, const BeaconMap& map,
                                                 const InputLog<RecordedInput>& log);

}  // namespace beaconloc::scan
