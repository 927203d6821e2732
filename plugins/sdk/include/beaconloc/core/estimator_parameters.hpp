#pragma once
// An estimator's parameters (the --param NAME=VALUE options), read through one mechanism: each
// parameter is declared once, where the estimator reads it, with its default, its valid range
// and its kind (a real number, a whole number, a flag). A value out of its range or of the wrong
// kind, and a name no estimator read asked for (a typo), are refused when the estimator is
// created, that is at the localizer's start, with a message naming the parameter, the value and
// the range (or the known names). No value is converted before it is checked.
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"

namespace beaconloc {

// The values a real parameter may take: from min to max, each end included or not.
struct ParameterRange {
  double min = 0.0;
  double max = 0.0;
  bool min_included = true;
  bool max_included = true;

  static ParameterRange closed(double min, double max) { return {min, max, true, true}; }  // [min, max]
  static ParameterRange above(double min, double max) { return {min, max, false, true}; }  // (min, max]
  static ParameterRange open(double min, double max) { return {min, max, false, false}; }  // (min, max)
  bool contains(double value) const;                                                       // false for NaN
  std::string to_string() const;                                                           // "(0, 1000]"
};

// The ranges of parameters several estimators share, stated once.
namespace parameter_ranges {
// A chi-square gate (NIS): positive; 1000 (31.6 sigma on one dof) is as good as no gate.
inline const ParameterRange kChiSquareGate = ParameterRange::above(0.0, 1000.0);
// The same where 0 switches the gate off.
inline const ParameterRange kChiSquareGateOrOff = ParameterRange::closed(0.0, 1000.0);
// Durations of data time (odometry gaps, measurement ages): positive, and at most the 10 s
// after which a pose without a correction is lost (StalenessPolicy::lost_after_ns).
inline const ParameterRange kDataDurationS =
    ParameterRange::above(0.0, ns_to_s(StalenessPolicy{}.lost_after_ns));
// Standard deviations of a position (m): positive, at most the size of a building.
inline const ParameterRange kPositionSigmaM = ParameterRange::above(0.0, 100.0);
// Standard deviations of a heading (rad): positive, at most a half turn.
inline const ParameterRange kHeadingSigmaRad = ParameterRange::above(0.0, M_PI);
}  // namespace parameter_ranges

class EstimatorParameterError : public std::invalid_argument {
 public:
  enum class Reason {
    kUnknownName,  // no read of the estimator asked for it
    kOutOfRange,   // outside the parameter's range (or not finite)
    kNotWhole,     // a count that is not a whole number
    kNotAFlag,     // a flag that is neither 0 nor 1
  };
  EstimatorParameterError(Reason reason, std::string parameter, const std::string& message)
      : std::invalid_argument(message), reason_(reason), parameter_(std::move(parameter)) {}
  Reason reason() const { return reason_; }
  const std::string& parameter() const { return parameter_; }  // for kUnknownName, the first unknown

 private:
  Reason reason_;
  std::string parameter_;
};

class ParameterReader {
 public:
  // estimator names the estimator in the messages.
  ParameterReader(const EstimatorConfig& config, std::string estimator);

  // The value given for name, or fallback; throws EstimatorParameterError (kOutOfRange) when the
  // value is outside range. The fallback must lie inside it (std::logic_error otherwise).
  double real(const std::string& name, double fallback, const ParameterRange& range);
  // A whole number in [min, max]: the value is checked for its range and for being whole before
  // it is converted (kOutOfRange, kNotWhole).
  int count(const std::string& name, int fallback, int min, int max);
  // 0 or 1 (kNotAFlag otherwise).
  bool flag(const std::string& name, bool fallback);
  // Throws EstimatorParameterError (kUnknownName) naming every given parameter no read asked
  // for, and listing the ones that were.
  void finish() const;
  // The names read so far, in the order they were read.
  const std::vector<std::string>& known() const { return known_; }

 private:
  const double* given(const std::string& name);
  [[noreturn]] void refuse(EstimatorParameterError::Reason reason, const std::string& name, double value,
                           const std::string& expected) const;

  std::map<std::string, double> parameters_;
  std::string estimator_;
  std::vector<std::string> known_;
};

}  // namespace beaconloc
