// Fuzz target: the beacon map as a participant receives it from the bus (beaconloc/beacon_map,
// from a gateway or anything on the domain): bytes deserialized as a CDR
// beaconloc::msg::BeaconMap by the type support the participants register
// (dds::CheckedType<BeaconMapPubSubType>, as Fast DDS calls it), then converted into the core's
// BeaconMap as the decoder and the localizer convert it (dds::from_msg). No DDS participant.
// Beyond "no crash, no undefined behaviour, no allocation out of proportion to the input":
// every beacon of the message is in the map under its id, the map has no more beacons than the
// message, and the map survives the way back to the wire (to_msg) and again from it unchanged.
#include <beaconlocPubSubTypes.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "beaconloc/dds/checked_type.hpp"
#include "beaconloc/dds/convert.hpp"

namespace {

using namespace beaconloc;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// The same number, NaN included (bit for bit).
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return 0;  // a beacon map is a few kB; larger inputs only slow the search
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  dds::CheckedType<msg::BeaconMapPubSubType> type;  // what the readers deserialize with
  msg::BeaconMap m;
  if (!type.deserialize(&payload, &m)) return 0;  // Fast DDS drops a sample it cannot read
  const BeaconMap map = dds::from_msg(m);
  check(map.size() <= m.beacons().size());
  for (const auto& b : m.beacons()) check(map.find(b.id()) != nullptr);
  const BeaconMap back = dds::from_msg(dds::to_msg(map, m.frame_id()));
  check(back.size() == map.size());
  for (const auto& b : map.beacons()) {
    const Beacon* again = back.find(b.id);
    check(again && again->group == b.group);
    for (int i = 0; i < 3; ++i) check(same(again->position_map_m[i], b.position_map_m[i]));
  }
  return 0;
}
