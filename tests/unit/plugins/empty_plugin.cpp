// A plugin that registers no estimator.
#include "beaconloc/core/estimator_plugin.hpp"

BEACONLOC_ESTIMATOR_PLUGIN();
