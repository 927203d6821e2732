#pragma once
// Keeps the latest Diagnostics of every participant on the bus (monitor, tests).
#include <beaconloc.h>

#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc {

class DiagnosticsRecorder {
 public:
  explicit DiagnosticsRecorder(const dds::DdsOptions& dds);
  ~DiagnosticsRecorder();
  std::map<std::string, msg::Diagnostics> latest() const;  // by participant name

 private:
  mutable std::mutex mutex_;
  std::map<std::string, msg::Diagnostics> latest_;
  dds::Participant participant_;
};

// One line per participant: accepted, rejected by reason, deadline misses, status.
void print_diagnostics(const std::map<std::string, msg::Diagnostics>& latest, std::ostream& out);

}  // namespace beaconloc
