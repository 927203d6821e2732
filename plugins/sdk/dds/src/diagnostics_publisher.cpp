#include "beaconloc/dds/diagnostics_publisher.hpp"

#include <beaconlocPubSubTypes.h>

namespace beaconloc::dds {

DiagnosticsPublisher::DiagnosticsPublisher(Participant& participant,
                                           std::function<msg::Diagnostics()> snapshot)
    : participant_(participant),
      snapshot_(std::move(snapshot)),
      writer_(participant.writer<msg::DiagnosticsPubSubType>(kDiagnosticsTopic)),
      task_(std::make_unique<PeriodicTask>(kDiagnosticsPeriod, [this] { publish_now(); })) {}

void DiagnosticsPublisher::publish_now() {
  msg::Diagnostics d = snapshot_();
  // Samples no type support could read (Fast DDS dropped them), whatever the participant.
  if (const std::uint64_t undecodable = participant_.undecodable_samples()) {
    msg::RejectionCount rc;
    rc.reason("undecodable_sample");
    rc.count(undecodable);
    d.rejected().push_back(rc);
  }
  writer_->write(&d);
}

void DiagnosticsPublisher::stop() {
  if (!task_) return;
  task_.reset();
  publish_now();
}

}  // namespace beaconloc::dds
