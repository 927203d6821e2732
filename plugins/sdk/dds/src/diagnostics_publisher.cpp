#include "beaconloc/dds/diagnostics_publisher.hpp"

#include <beaconlocPubSubTypes.h>

namespace beaconloc::dds {

DiagnosticsPublisher::DiagnosticsPublisher(Participant& participant,
                                           std::function<msg::Diagnostics()> snapshot)
    : snapshot_(std::move(snapshot)),
      writer_(participant.writer<msg::DiagnosticsPubSubType>(kDiagnosticsTopic)),
      task_(std::make_unique<PeriodicTask>(std::chrono::seconds(1), [this] { publish_now(); })) {}

void DiagnosticsPublisher::publish_now() {
  msg::Diagnostics d = snapshot_();
  writer_->write(&d);
}

void DiagnosticsPublisher::stop() {
  if (!task_) return;
  task_.reset();
  publish_now();
}

}  // namespace beaconloc::dds
