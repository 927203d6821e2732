#include "frame_rejection.hpp"

namespace beaconloc::serial {

const char* to_string(FrameRejection rejection) {
  switch (rejection) {
    case FrameRejection::kGarbage:
      return "garbage";
    case FrameRejection::kBadChecksum:
      return "bad_checksum";
    case FrameRejection::kBadLength:
      return "bad_length";
    case FrameRejection::kUnknownType:
      return "unknown_type";
    case FrameRejection::kUnknownVersion:
      return "unknown_version";
    case FrameRejection::kReservedBitsSet:
      return "reserved_bits_set";
    case FrameRejection::kDuplicate:
      return "duplicate";
    case FrameRejection::kTruncated:
      return "truncated";
  }
  return "unknown_frame_rejection";
}

}  // namespace beaconloc::serial
