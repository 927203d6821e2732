#include "beaconloc/core/estimator_parameters.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace beaconloc {
namespace {

// The shortest text that reads back as the same double ("-1", "0.35", "1e+300").
std::string number(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

}  // namespace

bool ParameterRange::contains(double v) const {
  const bool above_min = min_included ? v >= min : v > min;
  const bool below_max = max_included ? v <= max : v < max;
  return above_min && below_max;  // NaN compares false
}

std::string ParameterRange::to_string() const {
  return std::string(min_included ? "[" : "(") + number(min) + ", " + number(max) +
         (max_included ? "]" : ")");
}

ParameterReader::ParameterReader(const EstimatorConfig& config, std::string estimator)
    : parameters_(config.parameters), estimator_(std::move(estimator)) {}

const double* ParameterReader::given(const std::string& name) {
  if (std::find(known_.begin(), known_.end(), name) == known_.end()) known_.push_back(name);
  const auto it = parameters_.find(name);
  return it == parameters_.end() ? nullptr : &it->second;
}

void ParameterReader::refuse(EstimatorParameterError::Reason reason, const std::string& name, double value,
                             const std::string& expected) const {
  throw EstimatorParameterError(reason, name,
                                estimator_ + ": parameter " + name + "=" + number(value) + " " + expected);
}

double ParameterReader::real(const std::string& name, double fallback, const ParameterRange& range) {
  if (!range.contains(fallback))
    throw std::logic_error(estimator_ + ": default of " + name + " out of its range");
  const double* v = given(name);
  if (!v) return fallback;
  if (!range.contains(*v)) {
    refuse(EstimatorParameterError::Reason::kOutOfRange, name, *v, "is outside " + range.to_string());
  }
  return *v;
}

int ParameterReader::count(const std::string& name, int fallback, int min, int max) {
  if (fallback < min || fallback > max)
    throw std::logic_error(estimator_ + ": default of " + name + " out of its range");
  const double* v = given(name);
  if (!v) return fallback;
  const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
  // Range first: only a double within [min, max] (both ints) converts to int without UB.
  if (!(*v >= static_cast<double>(min) && *v <= static_cast<double>(max))) {
    refuse(EstimatorParameterError::Reason::kOutOfRange, name, *v, "is outside " + range);
  }
  if (std::floor(*v) != *v) {
    refuse(EstimatorParameterError::Reason::kNotWhole, name, *v,
           "is not a whole number (a count in " + range + ")");
  }
  return static_cast<int>(*v);
}

bool ParameterReader::flag(const std::string& name, bool fallback) {
  const double* v = given(name);
  if (!v) return fallback;
  if (*v != 0.0 && *v != 1.0)
    refuse(EstimatorParameterError::Reason::kNotAFlag, name, *v, "is not a flag (0 or 1)");
  return *v == 1.0;
}

void ParameterReader::finish() const {
  std::string unknown, first;
  for (const auto& [name, value] : parameters_) {
    if (std::find(known_.begin(), known_.end(), name) != known_.end()) continue;
    if (first.empty()) first = name;
    unknown += (unknown.empty() ? "'" : ", '") + name + "'";
  }
  if (unknown.empty()) return;
  std::string known;
  for (const auto& name : known_) known += (known.empty() ? "" : ", ") + name;
  throw EstimatorParameterError(
      EstimatorParameterError::Reason::kUnknownName, first,
      estimator_ + ": unknown parameter " + unknown + " (known: " + (known.empty() ? "none" : known) + ")");
}

}  // namespace beaconloc
