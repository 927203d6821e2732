#pragma once
// Publishes a participant's Diagnostics once a second, and a last time when stopped, then
// disposes its instance: a reader sees NOT_ALIVE_DISPOSED for a participant that stopped, and
// NOT_ALIVE_NO_WRITERS for one whose writer vanished (killed, or its liveliness lost). The
// snapshot function builds the sample (it runs on the publisher's own thread); the samples the
// participant could not deserialize are added as rejections "undecodable_sample".
#include <beaconloc.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"

namespace beaconloc::dds {

inline constexpr std::chrono::milliseconds kDiagnosticsPeriod{1000};
// A participant whose Diagnostics have not come for three periods is silent: hung, killed, or
// cut off (one late sample is no alarm). The monitor and the localizers' peers use this limit.
inline constexpr std::chrono::milliseconds kDiagnosticsSilentAfter = 3 * kDiagnosticsPeriod;

class DiagnosticsPublisher {
 public:
  DiagnosticsPublisher(Participant& participant, std::function<msg::Diagnostics()> snapshot);
  ~DiagnosticsPublisher() { stop(); }
  void publish_now();
  // Stops the periodic task, publishes the final counts and disposes the instance; idempotent.
  void stop();
  // writer_id() of this publisher's samples: a reader of Diagnostics tells its own from others'.
  std::string writer() const;

 private:
  const Participant& participant_;
  std::function<msg::Diagnostics()> snapshot_;
  std::mutex publish_mutex_;  // one report built and written at a time
  Writer writer_;
  std::unique_ptr<PeriodicTask> task_;
};

}  // namespace beaconloc::dds
