#pragma once
// decoder participant: RawTof -> BeaconRange through the TofDecoder core; Diagnostics at 1 Hz.
#include <beaconloc.h>

#include <atomic>
#include <memory>
#include <mutex>

#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/first_sample_watch.hpp"
#include "beaconloc/dds/participant.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {

class DecoderParticipant {
 public:
  DecoderParticipant(const dds::DdsOptions& dds, TofDecoderConfig config);
  void publish_diagnostics() { diagnostics_->publish_now(); }
  // Waits until the range writer has a matched reader (false on timeout).
  bool wait_for_readers(std::chrono::milliseconds timeout) const {
    return dds::wait_for_matched_readers({range_writer_}, timeout);
  }
  // TOFs taken from the bus and ranges written, for a throttle in the same process.
  std::uint64_t tofs_processed() const { return tofs_processed_.load(); }
  std::uint64_t ranges_written() const { return ranges_written_.load(); }
  // Whether a beacon map has reached it (see LocalizerParticipant::has_beacon_map).
  bool has_beacon_map() {
    std::lock_guard<std::mutex> lock(mutex_);
    return decoder_.has_beacon_map();
  }

 private:
  msg::Diagnostics diagnostics_snapshot();
  void on_raw_tof(const msg::RawTof& tof);
  void publish(const DecodedRange& range);

  std::mutex mutex_;
  TofDecoder decoder_;
  std::atomic<std::uint64_t> deadline_misses_{0};
  std::atomic<std::uint64_t> tof_writers_lost_{0};
  std::atomic<bool> tof_writer_lost_{false};  // lost, none alive since
  std::atomic<std::uint64_t> tofs_processed_{0};
  std::atomic<std::uint64_t> ranges_written_{0};
  // The entities, owned: the readers, declared last, stop first, before what they use goes.
  dds::Participant participant_;
  dds::Writer range_writer_;
  // Before diagnostics_, which reports its count: it goes after the Diagnostics task stops.
  std::unique_ptr<dds::FirstSampleWatch> map_reader_;  // recreated when mute (first_sample_watch.hpp)
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
  dds::Reader tof_reader_;
};

}  // namespace beaconloc
