#pragma once
// Estimator plugins built out of tree (core/estimator_plugin.hpp), loaded at run time: each file,
// or each *.so of a directory, is opened once per process, checked, and its estimators added to
// EstimatorRegistry::instance(), where --estimator finds them. A plugin stays loaded until the
// process ends (its estimators' code is in it).
#include <stdexcept>
#include <string>
#include <vector>

namespace beaconloc {

// Why a plugin was refused; the message names the file.
class EstimatorPluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads the plugins of `paths` (files, or directories whose *.so files are loaded in name order)
// and returns the names of the estimators they added. A file loaded before (the same real path)
// is skipped. Throws EstimatorPluginError naming the file when it cannot be opened (the loader's
// reason), is not an estimator plugin (no entry point), was built against another SDK ABI (both
// given), registers no estimator, or registers a name the localizer has already (built in, or
// from another plugin, named); a directory with no *.so file is refused too, and so is a
// directory holding any *.so that is not an estimator plugin (a helper library belongs elsewhere:
// every file of the directory is loaded). Nothing of a refused plugin is added. Each file is
// named on stderr before it is opened (its static initializers run then).
std::vector<std::string> load_estimator_plugins(const std::vector<std::string>& paths);

}  // namespace beaconloc
