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
  const auto add = [&d](const char* reason, std::uint64_t count) {
    if (count == 0) return;
    msg::RejectionCount rc;
    rc.reason(reason);
    rc.count(count);
    d.rejected().push_back(rc);
  };
  // Samples no type support could read (Fast DDS dropped them), whatever the participant.
  add("undecodable_sample", participant_.undecodable_samples());
  // Samples of a robot's measurements from a writer that may not speak for that robot.
  add("sample_for_another_robot", participant_.samples_for_another_robot());
  // Secured messages whose authentication tag failed (tampered), counted for the whole process.
  if (participant_.secured()) add("undecodable_secure_message", undecodable_secure_messages());
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
