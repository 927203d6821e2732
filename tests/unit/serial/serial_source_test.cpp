// SerialSource on a pseudo-terminal: each frame becomes the bus's sample with the numbers it
// carried, stamped on the host's clock; a line that goes silent or away is counted.
#include "serial_source.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "beaconloc/core/speed_of_sound.hpp"
#include "frame_encoder.hpp"
#include "pty.hpp"

namespace beaconloc::serial {
namespace {

using namespace std::chrono_literals;

StampNs host_now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Every event the source gives within 5 s, until `count` of them.
std::vector<SourceEvent> take(SerialSource& source, std::size_t count) {
  std::vector<SourceEvent> out;
  const auto end = std::chrono::steady_clock::now() + 5s;
  while (out.size() < count && std::chrono::steady_clock::now() < end) {
    source.advance(host_now() + kNsPerSecond, out);
    std::this_thread::sleep_for(5ms);
  }
  return out;
}

SerialSourceOptions options_on(const Pty& pty, Protocol protocol) {
  SerialSourceOptions o;
  o.device = pty.path();
  o.protocol = protocol;
  o.beacons = BeaconMap(std::vector<Beacon>{{1, {0, 0, 2}, 0}, {2, {3, 0, 2}, 0}});
  o.temperature_c = 18.0;
  return o;
}

TEST(SerialSource, FramesBecomeTheBusSamplesTheyCarry) {
  Pty pty;
  SerialSource source(options_on(pty, Protocol::kBeaconloc), host_now);
  const StampNs before = host_now();
  pty.write(encode(HeartbeatFrame{1'000'000}, 0));
  pty.write(encode(OdometryFrame{1'010'000, 0.25, -0.125, 0.33}, 1));
  TofFrame with_temperature{1'005'000, 6'000'000, 2, 1, true, 21.5};
  pty.write(encode(with_temperature, 2));
  TofFrame without{1'015'000, 5'000'000, 1, 0, false, 0.0};
  pty.write(encode(without, 3));
  const auto events = take(source, 3);
  const StampNs after = host_now();
  ASSERT_EQ(events.size(), 3u);
  const SourceEvent* odometry = nullptr;
  std::vector<const SourceEvent*> tofs;
  for (const auto& e : events) {
    if (e.kind == SourceEvent::Kind::kOdometry) odometry = &e;
    if (e.kind == SourceEvent::Kind::kTof) tofs.push_back(&e);
  }
  ASSERT_NE(odometry, nullptr);
  ASSERT_EQ(tofs.size(), 2u);
  EXPECT_EQ(odometry->odometry.wheel_velocity_right_mps, 0.25);
  EXPECT_EQ(odometry->odometry.wheel_velocity_left_mps, -0.125);
  EXPECT_EQ(odometry->odometry.wheel_base_m, 0.33);
  // The line's first odometry frame: dT the nominal 10 ms; seed 000's k_v |v| / dT per wheel.
  EXPECT_DOUBLE_EQ(odometry->odometry.wheel_velocity_covariance(0, 0), 4e-4 * 0.25 / 0.01);
  EXPECT_DOUBLE_EQ(odometry->odometry.wheel_velocity_covariance(1, 1), 4e-4 * 0.125 / 0.01);
  // Stamped on the host's clock: the heartbeat's arrival (within the test's reads of the clock)
  // plus the 10 ms of device time the odometry frame says it came after it.
  EXPECT_GE(odometry->stamp_ns, before);
  EXPECT_LE(odometry->stamp_ns, after + 10 * kNsPerMillisecond);
  for (const SourceEvent* t : tofs) {
    if (t->tof.beacon_id == 2) {
      EXPECT_EQ(t->tof.receiver_id, 1u);
      EXPECT_EQ(t->tof.tof_s, 6e-3);
      EXPECT_EQ(t->tof.beacon_temperature_c, 21.5);  // the module's own reading
      // Fired 5 ms of device time before the odometry's stamp: so on the host's clock.
      EXPECT_NEAR(static_cast<double>(odometry->stamp_ns - t->tof.fire_stamp_ns), 5e6, 0.1e6);
    } else {
      EXPECT_EQ(t->tof.beacon_id, 1u);
      EXPECT_EQ(t->tof.beacon_temperature_c, 18.0);  // none in the frame: the site's
    }
    EXPECT_EQ(t->stamp_ns, t->tof.fire_stamp_ns + s_to_ns(t->tof.tof_s));
  }
  EXPECT_EQ(source.input_rejections().rejected_total(), 0u);
}

TEST(SerialSource, MarvelmindDistancesTravelAsTofsTheDecoderTurnsBackIntoThem) {
  Pty pty;
  SerialSource source(options_on(pty, Protocol::kMarvelmind), host_now);
  DistancesFrame d;
  d.stamp_ms = 123'456;
  d.hedge_address = 7;
  d.slots = {{1, 2'345}, {2, 1'001}};
  pty.write(encode_marvelmind_distances(d));
  const auto events = take(source, 2);
  ASSERT_EQ(events.size(), 2u);
  for (const auto& e : events) {
    ASSERT_EQ(e.kind, SourceEvent::Kind::kTof);
    const double range_m = e.tof.tof_s * speed_of_sound_mps(e.tof.beacon_temperature_c);
    EXPECT_NEAR(range_m, e.tof.beacon_id == 1 ? 2.345 : 1.001, 1e-12);
    EXPECT_EQ(e.tof.receiver_id, 0u);
  }
}

TEST(SerialSource, ASilentLineIsCountedOnceAndADeviceThatGoesAwayToo) {
  Pty pty;
  SerialSource source(options_on(pty, Protocol::kBeaconloc), host_now);
  pty.write(encode(HeartbeatFrame{5}, 0));
  std::this_thread::sleep_for(std::chrono::nanoseconds(3 * SerialSource::kStalledNs));
  EXPECT_EQ(source.input_rejections().rejected("serial.stalled"), 1u);
  pty.close_master();
  const auto end = std::chrono::steady_clock::now() + 5s;
  while (source.input_rejections().rejected("serial.device_gone") == 0 &&
         std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(source.input_rejections().rejected("serial.device_gone"), 1u);
}

TEST(SerialSource, ADeviceThatCannotBeASerialLineIsRefusedAtOnce) {
  SerialSourceOptions o;
  o.device = "/dev/null";
  EXPECT_THROW(SerialSource(o, host_now), std::runtime_error);
  o.device = "/tmp/beaconloc-no-such-device";
  o.baud = 12345;
  EXPECT_THROW(SerialSource(o, host_now), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc::serial
