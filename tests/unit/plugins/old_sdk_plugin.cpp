// A plugin built against another SDK (an older one): its ABI string is not the localizer's, so it
// is refused before anything of it is used.
#include "beaconloc/core/estimator_plugin.hpp"

extern "C" __attribute__((visibility("default"))) const char* beaconloc_estimator_plugin_abi() {
  return "beaconloc-sdk 0.0; libstdc++ cxx11 abi 1; eigen 3.4.0; eigen static alignment 16; libstdc++ containers release";
}
extern "C" __attribute__((visibility("default"))) const beaconloc::EstimatorRegistry*
beaconloc_estimator_plugin_registry() {
  return nullptr;  // never asked: the ABI check refuses the plugin first
}
