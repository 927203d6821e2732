#pragma once
// Publishes a participant's Diagnostics once a second, and a last time when stopped. The
// snapshot function builds the sample (it runs on the publisher's own thread); the samples the
// participant could not deserialize are added as rejections "undecodable_sample".
#include <beaconloc.h>

#include <chrono>
#include <functional>
#include <memory>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"

namespace beaconloc::dds {

inline constexpr std::chrono::milliseconds kDiagnosticsPeriod{1000};

class DiagnosticsPublisher {
 public:
  DiagnosticsPublisher(Participant& participant, std::function<msg::Diagnostics()> snapshot);
  ~DiagnosticsPublisher() { stop(); }
  void publish_now();
  // Stops the periodic task and publishes the final counts; idempotent.
  void stop();

 private:
  const Participant& participant_;
  std::function<msg::Diagnostics()> snapshot_;
  eprosima::fastdds::dds::DataWriter* writer_;
  std::unique_ptr<PeriodicTask> task_;
};

}  // namespace beaconloc::dds
