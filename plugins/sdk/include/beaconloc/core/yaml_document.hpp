#pragma once
// Every YAML file the project reads (scenarios, map files) is loaded and its numbers converted
// here, strictly. yaml-cpp on its own keeps a key given twice in a mapping (iterating shows both
// pairs, node[key] returns the first: a second `range_sigma_m` line was silently ignored), reads
// only the first document of a file, and converts numbers its own way ("010" is 8, "0x10" 16,
// ".inf" infinite). load_yaml refuses a key repeated in any mapping at any depth, a key that is
// an alias, and a second document; yaml_number reads a scalar with core/decimal.hpp's parser.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "beaconloc/core/decimal.hpp"

namespace beaconloc {

class YamlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The document of `text`. Throws YamlError "<origin>:<line>: <what>": "not valid YAML: ...",
// "'robot.wheel_base_m' is repeated (first at line 7)", "'a.b' has a key that is an alias",
// "a second YAML document (a file holds one)". Keys are named by their dotted path, list items by
// their index ("beacons[2].id").
YAML::Node load_yaml(const std::string& text, const std::string& origin);

// A scalar's number (core/decimal.hpp); kNotDecimal for a node that is not a scalar.
template <class T>
NumberError yaml_number(const YAML::Node& node, T& out) {
  if (!node.IsScalar()) return NumberError::kNotDecimal;
  return parse_decimal(node.Scalar(), out);
}

}  // namespace beaconloc
