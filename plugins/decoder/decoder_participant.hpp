#pragma once
// decoder participant: RawTof -> BeaconRange through the TofDecoder core; Diagnostics at 1 Hz.
#include <atomic>
#include <memory>
#include <mutex>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {

class DecoderParticipant {
 public:
  DecoderParticipant(const dds::DdsOptions& dds, TofDecoderConfig config);
  ~DecoderParticipant();
  void publish_diagnostics();

 private:
  class Listener;
  void on_raw_tof(eprosima::fastdds::dds::DataReader* reader);
  void on_beacon_map(eprosima::fastdds::dds::DataReader* reader);

  std::mutex mutex_;
  TofDecoder decoder_;
  std::atomic<std::uint64_t> deadline_misses_{0};
  std::unique_ptr<Listener> listener_;
  dds::Participant participant_;
  eprosima::fastdds::dds::DataWriter* range_writer_;
  eprosima::fastdds::dds::DataWriter* diagnostics_writer_;
  eprosima::fastdds::dds::DataReader* map_reader_;
  eprosima::fastdds::dds::DataReader* tof_reader_;
  std::unique_ptr<dds::PeriodicTask> diagnostics_task_;
};

}  // namespace beaconloc
