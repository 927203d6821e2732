#pragma once
// Why the serial line's parser refused bytes (docs/serial-protocol.md, "What the gateway does with
// each fault"): one enumerator per fault, each with a stable snake_case name (to_string) for
// diagnostics. Code decides on the enumerator, never on the name.
#include <cstddef>
#include <cstdint>
#include <ostream>

namespace beaconloc::serial {

enum class FrameRejection : std::uint8_t {
  kGarbage,          // a run of bytes skipped while looking for a sync (bytes: Counts::garbage_bytes)
  kBadChecksum,      // the CRC over the frame does not match
  kBadLength,        // a known type whose length field is not that type's length (judged on the header)
  kUnknownType,      // beaconloc: a type version 1 does not define (judged on the header)
  kUnknownVersion,   // beaconloc: a version other than 1 (judged on the header)
  kReservedBitsSet,  // checksum good, but reserved flag bits or reserved bytes are not zero
  kDuplicate,        // beaconloc: the sequence number of the frame before it (a frame sent twice)
  kTruncated,        // a frame begun when the line went away (FrameParser::reset_partial)
};
inline constexpr std::size_t kFrameRejectionCount = static_cast<std::size_t>(FrameRejection::kTruncated) + 1;

// The stable name.
const char* to_string(FrameRejection rejection);
inline std::ostream& operator<<(std::ostream& out, FrameRejection rejection) {
  return out << to_string(rejection);
}

}  // namespace beaconloc::serial
