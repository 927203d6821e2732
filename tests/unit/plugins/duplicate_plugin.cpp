// A plugin whose estimator takes a name the localizer has already (the built-in range_ekf). It is
// refused before its factory could ever be called.
#include "beaconloc/core/estimator_plugin.hpp"

BEACONLOC_REGISTER_ESTIMATOR("range_ekf", "a second range_ekf", "default.yaml",
                             [](const beaconloc::EstimatorConfig&) {
                               return std::unique_ptr<beaconloc::Estimator>();
                             });

BEACONLOC_ESTIMATOR_PLUGIN();
