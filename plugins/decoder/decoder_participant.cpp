#include "decoder_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

DecoderParticipant::DecoderParticipant(const dds::DdsOptions& dds, TofDecoderConfig config)
    : decoder_(config),
      participant_(dds, "beaconloc.decoder"),
      range_writer_(participant_.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic)) {
  map_reader_ = std::make_unique<dds::FirstSampleWatch>([this](std::function<void()> heard) {
    return participant_.subscribe<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, [this, heard](const msg::BeaconMap& m) {
      heard();
      std::vector<DecodedRange> held;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        held = decoder_.on_beacon_map(dds::from_msg(m));
      }
      for (const auto& range : held) publish(range);
    });
  }, [this] { return tofs_processed_.load() > 0; });  // the gateway heard: its map should come too
  dds::ReaderEvents<msg::RawTof> tof_events;
  tof_events.deadline_misses = &deadline_misses_;
  tof_events.writers_lost = &tof_writers_lost_;
  tof_events.lost_and_none_alive = &tof_writer_lost_;
  tof_reader_ = participant_.subscribe<msg::RawTofPubSubType>(
      dds::kRawTofTopic, [this](const msg::RawTof& m) { on_raw_tof(m); }, tof_events);
  diagnostics_ =
      std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] { return diagnostics_snapshot(); });
}

void DecoderParticipant::on_raw_tof(const msg::RawTof& m) {
  DecodeOutcome outcome;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    outcome = decoder_.decode(m.robot_id(), dds::from_msg(m));
  }
  if (outcome.range) publish(*outcome.range);
  ++tofs_processed_;  // after the range is written: a throttle never sees the TOF done, the range not
}

void DecoderParticipant::publish(const DecodedRange& d) {
  msg::BeaconRange out;
  out.robot_id(d.robot_id);
  out.beacon_id(d.range.beacon_id);
  out.receiver_id(d.range.receiver_id);
  out.stamp_ns(d.range.stamp_ns);
  out.range_m(d.range.range_m);
  out.variance_m2(d.range.variance_m2);
  out.quality(d.quality);
  out.association(d.associated ? msg::RANGE_ASSOCIATION_BY_ID : msg::RANGE_ASSOCIATION_UNASSOCIATED);
  out.source_sequence_number(d.source_sequence_number);
  range_writer_->write(&out);
  ++ranges_written_;
}

msg::Diagnostics DecoderParticipant::diagnostics_snapshot() {
  std::lock_guard<std::mutex> lock(mutex_);
  msg::ParticipantStatus status = msg::PARTICIPANT_STATUS_OK;
  std::string message;
  if (!decoder_.has_beacon_map()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "waiting for the beacon map";
  } else if (tof_writer_lost_.load()) {
    // A gateway was there and is gone (liveliness lost: its process died or hung).
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "no live TOF writer: the gateway was lost";
  }
  RejectionCounter counts = decoder_.counts();
  counts.reject(dds::kMapReaderRecreated, map_reader_->recreated());
  auto d = dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), counts, deadline_misses_.load(), status,
                                 message);
  d.writers_lost(tof_writers_lost_.load());
  return d;
}

}  // namespace beaconloc
