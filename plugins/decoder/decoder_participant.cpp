#include "decoder_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::SampleInfo;

class DecoderParticipant::Listener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  explicit Listener(DecoderParticipant& owner) : owner_(owner) {}
  void on_data_available(DataReader* reader) override {
    if (reader->get_topicdescription()->get_name() == dds::kRawTofTopic.name) {
      owner_.on_raw_tof(reader);
    } else {
      owner_.on_beacon_map(reader);
    }
  }
  void on_requested_deadline_missed(DataReader*,
                                    const eprosima::fastdds::dds::RequestedDeadlineMissedStatus&) override {
    ++owner_.deadline_misses_;
  }

 private:
  DecoderParticipant& owner_;
};

DecoderParticipant::DecoderParticipant(const dds::DdsOptions& dds, TofDecoderConfig config)
    : decoder_(config),
      listener_(std::make_unique<Listener>(*this)),
      participant_(dds, "beaconloc.decoder"),
      range_writer_(participant_.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic)),
      diagnostics_writer_(participant_.writer<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic)),
      map_reader_(participant_.reader<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, listener_.get())),
      tof_reader_(participant_.reader<msg::RawTofPubSubType>(dds::kRawTofTopic, listener_.get())),
      diagnostics_task_(std::make_unique<dds::PeriodicTask>(std::chrono::seconds(1),
                                                            [this] { publish_diagnostics(); })) {}

DecoderParticipant::~DecoderParticipant() {
  diagnostics_task_.reset();
  publish_diagnostics();
  participant_.close();  // no callback may run once the listener is gone
}

void DecoderParticipant::on_beacon_map(DataReader* reader) {
  msg::BeaconMap m;
  SampleInfo info;
  while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    std::lock_guard<std::mutex> lock(mutex_);
    decoder_.set_beacon_map(dds::from_msg(m));
  }
}

void DecoderParticipant::on_raw_tof(DataReader* reader) {
  msg::RawTof m;
  SampleInfo info;
  while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    DecodeOutcome outcome;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      outcome = decoder_.decode(m.robot_id(), dds::from_msg(m));
    }
    if (!outcome.range) continue;
    const DecodedRange& d = *outcome.range;
    msg::BeaconRange out;
    out.robot_id(m.robot_id());
    out.beacon_id(d.range.beacon_id);
    out.receiver_id(d.range.receiver_id);
    out.stamp_ns(d.range.stamp_ns);
    out.range_m(d.range.range_m);
    out.variance_m2(d.range.variance_m2);
    out.quality(d.quality);
    out.association(d.associated ? msg::RANGE_ASSOCIATION_BY_ID : msg::RANGE_ASSOCIATION_UNASSOCIATED);
    out.source_sequence_number(d.source_sequence_number);
    range_writer_->write(&out);
  }
}

void DecoderParticipant::publish_diagnostics() {
  msg::Diagnostics d;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool has_map = decoder_.has_beacon_map();
    d = dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), decoder_.counts(),
                              deadline_misses_.load(),
                              has_map ? msg::PARTICIPANT_STATUS_OK : msg::PARTICIPANT_STATUS_DEGRADED,
                              has_map ? "" : "waiting for the beacon map");
  }
  diagnostics_writer_->write(&d);
}

}  // namespace beaconloc
