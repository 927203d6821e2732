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
  // One report at a time, built and written together: the periodic task's and one asked for
  // (a localizer shard's change) never cross, an older report written last.
  std::lock_guard<std::mutex> lock(publish_mutex_);
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
  // Every participant's Diagnostics are keyed by its name (dds::make_diagnostics).
  msg::Diagnostics key;
  key.participant(participant_.name());
  writer_->dispose(&key, eprosima::fastdds::dds::HANDLE_NIL);
  // Readers acknowledge both at once when nothing is lost; a lost one is repaired only while the
  // writer lives. Bounded: a reader that died unnoticed never acknowledges.
  writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 200'000'000));
}

std::string DiagnosticsPublisher::writer() const { return writer_id(writer_->get_instance_handle()); }

}  // namespace beaconloc::dds
