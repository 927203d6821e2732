#pragma once
// A deployment's keystore for a test, made by the script a deployment uses
// (scripts/deployment-keys.sh), in a directory of the test's.
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace beaconloc::testing {

inline const std::string kDeploymentKeysScript =
    std::string(BEACONLOC_SOURCE_DIR) + "/scripts/deployment-keys.sh";

// Runs `deployment-keys.sh ARGS` (quiet); throws with the command when it fails.
inline void deployment_keys(const std::string& args) {
  const std::string command = "bash " + kDeploymentKeysScript + " " + args + " >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("failed: " + command);
}

// A keystore at `dir` with every role's enclave for the robots (comma separated).
inline std::string make_deployment(const std::string& dir, const std::string& robots) {
  deployment_keys("deployment " + dir + " " + robots);
  return dir;
}

}  // namespace beaconloc::testing
