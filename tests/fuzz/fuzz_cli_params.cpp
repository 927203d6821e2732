// Fuzz target: the parser of the estimator parameters given on the command line
// (`--param NAME=VALUE`, repeatable; plugins/sdk/src/estimator.cpp), which `localizer`, `run`,
// `demo` and `accuracy` share. Input: one item per line. It must return the parameters or throw
// std::invalid_argument; every parameter it returns has a name and a finite value given by an
// item.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream text(std::string(reinterpret_cast<const char*>(data), size));
  std::vector<std::string> items;
  for (std::string line; std::getline(text, line);) items.push_back(line);
  try {
    const auto parameters = beaconloc::parse_estimator_parameters(items, "--param");
    for (const auto& [name, value] : parameters) {
      bool given = false;
      for (const auto& item : items) given = given || item.rfind(name + "=", 0) == 0;
      if (name.empty() || !std::isfinite(value) || !given) __builtin_trap();
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
