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
#include <fastcdr/exceptions/Exception.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <atomic>
#include <cstdint>

namespace beaconloc::dds {

template <class PubSubType>
class CheckedType : public PubSubType {
 public:
  // refused: incremented for every payload refused (may be null); must outlive the type.
  explicit CheckedType(std::atomic<std::uint64_t>* refused = nullptr) : refused_(refused) {}

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (PubSubType::deserialize(payload, data)) return true;
    } catch (const eprosima::fastcdr::exception::Exception&) {
    }
    if (refused_) ++*refused_;
    return false;
  }

 private:
  std::atomic<std::uint64_t>* refused_;
};

}  // namespace beaconloc::dds
