#pragma once
// Estimators built out of tree, against the installed SDK (find_package(beaconloc), docs/deployment.md,
// examples/estimator_plugin/): a shared library whose estimators register with
// BEACONLOC_REGISTER_ESTIMATOR as the built-in ones do, and which says once, at namespace scope,
//   BEACONLOC_ESTIMATOR_PLUGIN();
// Build it with beaconloc_add_estimator_plugin() (cmake/beaconlocPlugin.cmake). The localizer loads
// it with --estimator-plugin FILE (or a directory of them: plugins/localizer/estimator_plugins.hpp),
// refuses it unless its SDK ABI (below) is the localizer's own, and adds its estimators to its
// registry: then --estimator NAME takes them like any other.
#include <Eigen/Core>
#include <string>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/sdk_version.hpp"

#define BEACONLOC_STRINGIFY_INNER(x) #x
#define BEACONLOC_STRINGIFY(x) BEACONLOC_STRINGIFY_INNER(x)

// What must be the same in the localizer and a plugin for the C++ types they pass each other
// (Estimator's virtual interface, EstimatorConfig, std::string and std::map, Eigen's fixed-size
// matrices) to have one layout: the SDK's major and minor version (the estimator API changes only
// with them; a patch release keeps it), libstdc++'s string ABI, Eigen's version and its static
// alignment (set by the target's SIMD flags, e.g. -mavx), and whether libstdc++'s debug
// containers (_GLIBCXX_DEBUG, another std::map layout) are on.
#ifdef _GLIBCXX_DEBUG
#define BEACONLOC_SDK_ABI_CONTAINERS "debug"
#else
#define BEACONLOC_SDK_ABI_CONTAINERS "release"
#endif
// clang-format off
#define BEACONLOC_SDK_ABI                                                                               \
  "beaconloc-sdk " BEACONLOC_STRINGIFY(BEACONLOC_SDK_VERSION_MAJOR) "."                                   \
      BEACONLOC_STRINGIFY(BEACONLOC_SDK_VERSION_MINOR)                                                     \
  "; libstdc++ cxx11 abi " BEACONLOC_STRINGIFY(_GLIBCXX_USE_CXX11_ABI)                                    \
  "; eigen " BEACONLOC_STRINGIFY(EIGEN_WORLD_VERSION) "." BEACONLOC_STRINGIFY(EIGEN_MAJOR_VERSION) "."      \
      BEACONLOC_STRINGIFY(EIGEN_MINOR_VERSION)                                                             \
  "; eigen static alignment " BEACONLOC_STRINGIFY(EIGEN_MAX_STATIC_ALIGN_BYTES)                           \
  "; libstdc++ containers " BEACONLOC_SDK_ABI_CONTAINERS
// clang-format on

namespace beaconloc {

// The entry points a plugin exports (C linkage, so that they can be looked up and called before
// anything of C++ is known to match): its SDK ABI, then, only when that is the localizer's, its
// registry.
constexpr const char* kPluginAbiSymbol = "beaconloc_estimator_plugin_abi";
constexpr const char* kPluginRegistrySymbol = "beaconloc_estimator_plugin_registry";
using PluginAbiFunction = const char* (*)();
using PluginRegistryFunction = const EstimatorRegistry* (*)();

}  // namespace beaconloc

// Once per plugin, at namespace scope in one of its .cpp files.
#define BEACONLOC_ESTIMATOR_PLUGIN()                                                               \
  extern "C" __attribute__((visibility("default"))) const char* beaconloc_estimator_plugin_abi() { \
    return BEACONLOC_SDK_ABI;                                                                      \
  }                                                                                                \
  extern "C" __attribute__((visibility("default"))) const ::beaconloc::EstimatorRegistry*          \
  beaconloc_estimator_plugin_registry() {                                                          \
    return &::beaconloc::EstimatorRegistry::instance();                                            \
  }                                                                                                \
  static_assert(true, "a semicolon after BEACONLOC_ESTIMATOR_PLUGIN()")
