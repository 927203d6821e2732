// Fuzz target: the beacon map as a participant receives it from the bus (beaconloc/beacon_map,
// from a gateway or anything on the domain): bytes deserialized as a CDR
// beaconloc::msg::BeaconMap by the type support the participants register
// (dds::CheckedType<BeaconMapPubSubType>, as Fast DDS calls it), then converted into the core's
// beacons (dds::from_msg) and checked whole as the decoder, the localizer and the bridge check
// them (BeaconMap::from, check_beacons). No DDS participant. Beyond "no crash, no undefined
// behaviour, no allocation out of proportion to the input": a refused map names its problem; a
// taken one has every beacon of the message under its id, finite and within bounds, and
// survives the way back to the wire (to_msg) and again from it unchanged.
#include <beaconlocPubSubTypes.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

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
  // What the localizer, decoder and bridge do with it: check it whole (check_beacons), then take
  // it or refuse it with a reason. A refused map names a problem that is there; a taken one
  // holds every beacon sent, each finite and in bounds, and survives the wire unchanged.
  const BeaconList sent = dds::from_msg(m);
  check(sent.map_frame.size() + sent.group_frame.size() == m.beacons().size());
  BeaconMapCheck verdict;
  const std::optional<BeaconMap> map = BeaconMap::from(sent, &verdict);
  check(map.has_value() == verdict.ok());
  if (!map) {
    check(verdict.problem != BeaconMapProblem::kNone);
    const std::string reason = to_string(verdict.problem);
    check(!reason.empty() && reason != "unknown");
    return 0;
  }
  // No id repeated: nothing overwritten; a locally referenced beacon never found as a map one.
  check(map->size() == sent.map_frame.size() && map->local_size() == sent.group_frame.size());
  for (const auto& b : sent.map_frame) {
    const Beacon* found = map->find(b.id);
    check(found != nullptr && found->position_map_m.allFinite() &&
          found->position_map_m.cwiseAbs().maxCoeff() <= kMaxMapCoordinateM);
  }
  for (const auto& b : sent.group_frame) check(!map->find(b.id) && map->find_local(b.id) && b.group != 0);
  BeaconMapCheck again_verdict;
  const std::optional<BeaconMap> back =
      BeaconMap::from(dds::from_msg(dds::to_msg(*map, m.frame_id())), &again_verdict);
  check(back.has_value() && back->size() == map->size() && *back == *map);
  for (const auto& b : map->beacons()) {
    const Beacon* again = back->find(b.id);
    check(again && again->group == b.group);
    for (int i = 0; i < 3; ++i) check(same(again->position_map_m[i], b.position_map_m[i]));
  }
  return 0;
}
