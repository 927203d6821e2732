#pragma once
// Keeps the latest Diagnostics of every participant on the bus (monitor, tests).
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>

#include <beaconloc.h>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc {

class DiagnosticsRecorder {
 public:
  explicit DiagnosticsRecorder(const dds::DdsOptions& dds);
  ~DiagnosticsRecorder();
  std::map<std::string, msg::Diagnostics> latest() const;  // by participant name

 private:
  class Listener;
  mutable std::mutex mutex_;
  std::map<std::string, msg::Diagnostics> latest_;
  std::unique_ptr<Listener> listener_;
  dds::Participant participant_;
  eprosima::fastdds::dds::DataReader* reader_;
};

// One line per participant: accepted, rejected by reason, deadline misses, status.
void print_diagnostics(const std::map<std::string, msg::Diagnostics>& latest, std::ostream& out);

}  // namespace beaconloc
