#pragma once
// The gateway's source on real receiver hardware: frames from a serial line (our protocol or
// Marvelmind's raw distances, docs/serial-protocol.md), each stamped on arrival, its device time
// mapped to the host's (DeviceClock), and turned into the bus's samples:
//  - a TOF frame: RawTof (fire time mapped; the frame's temperature, else the site's);
//  - a Marvelmind distance: RawTof at the reference temperature, tof = range / c(T), as a replayed
//    range travels (docs/replay-format.md), stamped at the measurement's mapped time;
//  - an odometry frame: Odometry, with seed 000's noise per wheel, sigma^2 = k_v |v| / dT, dT the
//    mapped time since the previous odometry frame (the nominal period for the first of a line or
//    of a device clock's new time line); a frame not after the one before is refused, counted;
//  - a heartbeat: nothing (it keeps the clock mapping).
// A reader thread reads the line; a device that goes away (USB unplugged) is reopened every
// kReopenPeriod. What the line did wrong is counted by reason (input_rejections, in the
// gateway's Diagnostics as source.serial.<reason>). Live: the source never ends. DDS-free.
#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "device_clock.hpp"
#include "frame_parser.hpp"
#include "serial_port.hpp"
#include "source.hpp"

namespace beaconloc {

struct SerialSourceOptions {
  std::string device;
  std::uint32_t baud = 115200;
  serial::Protocol protocol = serial::Protocol::kBeaconloc;
  BeaconMap beacons;        // the site's surveyed beacons (the line does not carry them)
  ReceiverArray receivers;  // the robot's receivers; default one at its centre
  // Air temperature for TOF frames that carry none, and the reference a Marvelmind distance is
  // expressed at (the decoder gets it back exactly).
  double temperature_c = 20.0;
  double odometry_k_v_m = 4e-4;     // seed 000 Sec. V
  double odometry_period_s = 0.01;  // dT of a line's first odometry frame
};

class SerialSource final : public Source {
 public:
  // A device that goes away is reopened this often while it is missing.
  static constexpr std::chrono::milliseconds kReopenPeriod{250};
  // No byte for this long, after the line spoke, is a stalled line, counted once per stall: a
  // receiver sends a heartbeat at least every 100 ms (docs/serial-protocol.md), so three are missing.
  static constexpr StampNs kStalledNs = 300 * kNsPerMillisecond;
  // Events held for the gateway: 10 s of a busy line (100 Hz odometry, 3 receivers at 5 Hz), far
  // more than the 10 ms between the gateway's steps.
  static constexpr std::size_t kMaxPending = 2000;

  using Clock = std::function<StampNs()>;  // the host's time, ns since the epoch
  // Opens the device (a missing one is waited for, counted) and starts reading. Throws
  // std::invalid_argument for a bad baud or option, std::runtime_error for a device that exists but
  // cannot be a serial line (not a terminal, no permission).
  SerialSource(SerialSourceOptions options, Clock now);
  ~SerialSource() override;

  void advance(StampNs until_ns, std::vector<SourceEvent>& out) override;
  bool exhausted() const override { return false; }
  bool finite() const override { return false; }
  BeaconMap beacon_map() const override { return options_.beacons; }
  ReceiverArray receivers() const override { return options_.receivers; }
  StampNs first_stamp_ns() const override { return started_ns_; }
  StampNs last_stamp_ns() const override { return started_ns_; }
  bool relative_stamps() const override { return false; }
  std::string describe() const override;
  RejectionCounter input_rejections() const override;

 private:
  void read_loop();
  // Under mutex_: the frames of one read, as events.
  void convert(const serial::Frame& frame);
  void push(const SourceEvent& e);
  void add_tof(StampNs fire_ns, double tof_s, std::uint32_t beacon_id, std::uint32_t receiver_id,
               double temperature_c);

  SerialSourceOptions options_;
  Clock now_;
  StampNs started_ns_;
  serial::SerialPort port_;
  mutable std::mutex mutex_;
  serial::FrameParser parser_;
  serial::DeviceClock clock_;
  std::deque<SourceEvent> pending_;  // the oldest dropped first when full (push)
  std::uint64_t sequence_ = 0;
  StampNs previous_odometry_ns_ = -1;  // the mapped stamp of the line's previous odometry frame
  std::uint64_t clock_resets_seen_ = 0;
  bool reopen_failure_counted_ = false;  // the reader thread's
  RejectionCounter counts_;  // the line's own: gone, reopened, stalled, open failures
  std::atomic<bool> stop_{false};
  std::thread reader_;  // last: stops before what it uses goes
};

}  // namespace beaconloc
