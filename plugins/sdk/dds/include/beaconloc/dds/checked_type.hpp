#pragma once
// A topic's type support that refuses a payload it cannot read instead of throwing. The
// generated deserialize() (fastddsgen 2.3) catches only a buffer too short; any other Fast CDR
// exception -- a first byte that is not 0, an encapsulation other than plain CDR (XCDR2 from
// another vendor, a corrupted or hostile sample) -- escapes Fast DDS's take_next_sample() into
// the reader's listener, and its key computation on the receive thread: std::terminate, the
// participant dies on one bad sample (found by tests/fuzz/fuzz_decoder_input; a reader process
// aborts on one RawTof sent with an XCDR2 encapsulation). Returning false makes Fast DDS 2.9 drop
// the sample. Each refusal is counted (Diagnostics: undecodable_sample); Fast DDS reads a sample
// of a keyed topic twice when its writer sent no key hash (for its key, then when it is taken),
// so such a sample counts twice.
//
// A payload that reads but is not well formed is refused the same way: an enumeration value the
// type does not define (Fast CDR reads an enum as a 32-bit integer and casts it unchecked: a
// Diagnostics status of 7 printed as "ok", one of 0xFFFFFFFF indexed a table at -1), a string
// with a control character (a robot id or a Diagnostics message carrying a newline or a terminal
// escape sequence would forge lines in the monitor's output and rows in the CSV files), or a name
// (robot id, estimator, participant) with a ',' or '"' (it would shift the columns of the CSV
// files, which write names unquoted). No reader
// ever sees a value its switch does not list or a string it cannot print. well_formed() holds one
// overload per beaconloc type; other types (the ROS 2 ones) are taken as they read.
#include <beaconloc.h>
#include <fastcdr/exceptions/Exception.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <atomic>
#include <cstdint>

namespace beaconloc::dds {

// True when every enumeration field of `m` holds a value its IDL type defines, no string field
// holds a control character (C0, DEL, C1) and no name holds ',' or '"'.
bool well_formed(const msg::RawTof& m);
bool well_formed(const msg::PulseArrival& m);
bool well_formed(const msg::BeaconRange& m);
bool well_formed(const msg::Odometry& m);
bool well_formed(const msg::LaserScan& m);
bool well_formed(const msg::PoseEstimate& m);
bool well_formed(const msg::EstimatorState& m);
bool well_formed(const msg::InitialPose& m);
bool well_formed(const msg::BeaconMap& m);
bool well_formed(const msg::BeaconCalibration& m);
bool well_formed(const msg::Diagnostics& m);
template <class Msg>
bool well_formed(const Msg&) {
  return true;  // a type of another system's (ROS 2): read as it is
}

template <class PubSubType>
class CheckedType : public PubSubType {
 public:
  // refused: incremented for every payload refused (may be null); must outlive the type.
  explicit CheckedType(std::atomic<std::uint64_t>* refused = nullptr) : refused_(refused) {}

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (PubSubType::deserialize(payload, data) &&
          well_formed(*static_cast<const typename PubSubType::type*>(data))) {
        return true;
      }
    } catch (const eprosima::fastcdr::exception::Exception&) {
    }
    if (refused_) ++*refused_;
    return false;
  }

 private:
  std::atomic<std::uint64_t>* refused_;
};

}  // namespace beaconloc::dds
