#pragma once
// decoder participant: RawTof -> BeaconRange through the TofDecoder core; Diagnostics at 1 Hz.
#include <beaconloc.h>

#include <atomic>
#include <memory>
#include <mutex>

#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/participant.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {

class DecoderParticipant {
 public:
  DecoderParticipant(const dds::DdsOptions& dds, TofDecoderConfig config);
  ~DecoderParticipant();

 private:
  msg::Diagnostics diagnostics_snapshot();
  void on_raw_tof(const msg::RawTof& tof);

  std::mutex mutex_;
  TofDecoder decoder_;
  std::atomic<std::uint64_t> deadline_misses_{0};
  dds::Participant participant_;
  eprosima::fastdds::dds::DataWriter* range_writer_;
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
};

}  // namespace beaconloc
