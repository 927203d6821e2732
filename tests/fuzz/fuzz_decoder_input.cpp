// Fuzz target: the decoder's input path as it runs live (plugins/decoder). Each step of an input
// either takes a RawTof from the wire -- bytes deserialized by the type support the participant
// registers for the topic (dds::CheckedType: CDR, encapsulation first), converted as the participant converts
// them (dds::from_msg) and decoded (TofDecoder::decode) -- or decodes the previous sample again (a
// duplicate), or with its firing stamp moved (late, early, stale), or delivers the beacon map (TOFs held
// until it arrives are then decoded). No DDS participant: nothing leaves the process. Beyond "no crash, no
// undefined behaviour": every TOF is accepted or rejected exactly once, counted; an accepted range is finite,
// within the configured limits, and arrives after its firing.
#include <beaconlocPubSubTypes.h>
#include <fastdds/rtps/common/SerializedPayload.h>
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "beaconloc/dds/checked_type.hpp"
#include "beaconloc/dds/convert.hpp"
#include "tof_decoder.hpp"

namespace {

using namespace beaconloc;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check_range(const DecodedRange& d, const TofDecoderConfig& config) {
  check(std::isfinite(d.range.range_m) && d.range.range_m >= config.min_range_m &&
        d.range.range_m <= config.max_range_m);
  check(std::isfinite(d.range.variance_m2) && d.range.variance_m2 > 0.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  TofDecoderConfig config;
  config.range_scale = in.ConsumeBool() ? 1.0 : 1.069;  // ultrasonic, or the CMU Plaza radios
  TofDecoder decoder(config);
  const BeaconMap map({{1, {0.0, 0.0, 2.0}, 0}, {2, {3.0, 0.0, 2.0}, 0}, {3, {0.0, 3.0, 2.0}, 1}});
  dds::CheckedType<msg::RawTofPubSubType> type;  // what the decoder's reader deserializes with

  std::uint64_t decoded = 0;  // TOFs handed to the decoder
  bool have_last = false;
  std::string last_robot;
  RawTofSample last;
  auto decode = [&](const std::string& robot, const RawTofSample& tof) {
    ++decoded;
    const DecodeOutcome out = decoder.decode(robot, tof);
    check(static_cast<int>(out.range.has_value()) + static_cast<int>(out.rejection.has_value()) +
              static_cast<int>(out.deferred) ==
          1);
    if (out.range) {
      check_range(*out.range, config);
      check(out.range->range.stamp_ns > tof.fire_stamp_ns);
    }
  };

  for (int step = 0; step < 64 && in.remaining_bytes() > 0; ++step) {
    switch (in.ConsumeIntegralInRange<int>(0, 3)) {
      case 0: {  // a sample from the wire
        const auto bytes = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 96));
        eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
        if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());
        payload.length = static_cast<std::uint32_t>(bytes.size());
        msg::RawTof m;
        if (!type.deserialize(&payload, &m)) break;  // Fast DDS drops a sample it cannot read
        last = dds::from_msg(m);
        last_robot = m.robot_id();
        have_last = true;
        decode(last_robot, last);
        break;
      }
      case 1:  // the same sample again
        if (have_last) decode(last_robot, last);
        break;
      case 2:  // the same beacon firing, stamped elsewhere (wrapping: any stamp the wire can carry)
        if (have_last) {
          last.fire_stamp_ns =
              static_cast<StampNs>(static_cast<std::uint64_t>(last.fire_stamp_ns) +
                                   static_cast<std::uint64_t>(in.ConsumeIntegral<std::int64_t>()));
          last.sequence_number += in.ConsumeIntegralInRange<std::uint64_t>(0, 2);
          decode(last_robot, last);
        }
        break;
      case 3:  // the beacon map arrives
        for (const auto& d : decoder.set_beacon_map(map)) check_range(d, config);
        break;
    }
  }
  for (const auto& d : decoder.set_beacon_map(map)) check_range(d, config);  // nothing stays held
  check(decoder.counts().accepted() + decoder.counts().rejected_total() == decoded);
  return 0;
}
