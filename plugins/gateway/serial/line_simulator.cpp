#include "line_simulator.hpp"

#include <cmath>
#include <iomanip>
#include <stdexcept>
#include <thread>

#include "beaconloc/core/speed_of_sound.hpp"
#include "frame_encoder.hpp"

namespace beaconloc {
namespace {

constexpr StampNs kStepNs = 5 * kNsPerMillisecond;
// A heartbeat when nothing else was sent for this long (docs/serial-protocol.md: at least every 100 ms).
constexpr StampNs kHeartbeatNs = 100 * kNsPerMillisecond;
constexpr auto kReopenPeriod = std::chrono::milliseconds(250);

}  // namespace

LineSimulator::LineSimulator(LineSimulatorOptions options, Source& source, Clock now)
    : options_(std::move(options)),
      source_(source),
      now_(std::move(now)),
      port_(options_.device, options_.baud),
      random_(options_.seed) {
  const serial::SerialPort::OpenResult opened = port_.open();
  if (!opened.ok()) throw std::runtime_error(opened.message);
  counter_start_ = random_() & 0xffffffffULL;  // a module powered on at any time
  if (!options_.truth_csv.empty()) {
    truth_.open(options_.truth_csv);
    if (!truth_) throw std::runtime_error("cannot write '" + options_.truth_csv + "'");
    truth_ << "stamp_ns,x_m,y_m,yaw_rad\n" << std::setprecision(12);
  }
}

std::uint32_t LineSimulator::device_counter(StampNs source_ns) const {
  // The module's clock: its counter's ticks since source time 0, drifting against the host's.
  const double ticks = static_cast<double>(source_ns) * (1.0 + options_.drift_ppm * 1e-6) /
                       (options_.protocol == serial::Protocol::kBeaconloc ? 1e3 : 1e6);
  return static_cast<std::uint32_t>((counter_start_ + static_cast<std::uint64_t>(std::llround(ticks))) &
                                    0xffffffffULL);
}

bool LineSimulator::stalled(StampNs source_ns) const {
  const double t = ns_to_s(source_ns);
  return options_.stall_at_s >= 0.0 && t >= options_.stall_at_s && t < options_.stall_at_s + options_.stall_s;
}

void LineSimulator::frames_of(const SourceEvent& e, std::vector<std::vector<std::uint8_t>>& out) {
  switch (e.kind) {
    case SourceEvent::Kind::kTof: {
      const RawTofSample& t = e.tof;
      if (!(t.tof_s >= 0.0 && t.tof_s < 4.29) || t.beacon_id > 0xffff || t.receiver_id > 0xff) {
        ++counts_.not_sendable;
        return;
      }
      if (options_.protocol == serial::Protocol::kMarvelmind) {
        if (t.receiver_id != 0 || t.beacon_id == 0 || t.beacon_id > 0xff)
          return;  // one mobile beacon, its own ids
        serial::DistancesFrame d;
        d.stamp_ms = device_counter(e.stamp_ns);
        d.hedge_address = 1;
        const double range_m = t.tof_s * speed_of_sound_mps(t.beacon_temperature_c);
        d.slots.push_back({static_cast<std::uint8_t>(t.beacon_id),
                           static_cast<std::uint32_t>(std::llround(range_m * 1e3))});
        out.push_back(serial::encode_marvelmind_distances(d));
        return;
      }
      serial::TofFrame f;
      f.fire_time_us = device_counter(t.fire_stamp_ns);
      f.tof_ns = static_cast<std::uint32_t>(std::llround(t.tof_s * 1e9));
      f.beacon_id = static_cast<std::uint16_t>(t.beacon_id);
      f.receiver_id = static_cast<std::uint8_t>(t.receiver_id);
      f.has_temperature = true;
      f.temperature_c = std::round(t.beacon_temperature_c * 100.0) / 100.0;
      out.push_back(serial::encode(f, sequence_++));
      return;
    }
    case SourceEvent::Kind::kOdometry: {
      if (options_.protocol == serial::Protocol::kMarvelmind) return;  // no wheels in Marvelmind's stream
      serial::OdometryFrame f;
      f.stamp_us = device_counter(e.stamp_ns);
      f.right_mps = std::round(e.odometry.wheel_velocity_right_mps * 1e6) / 1e6;
      f.left_mps = std::round(e.odometry.wheel_velocity_left_mps * 1e6) / 1e6;
      f.wheel_base_m = std::round(e.odometry.wheel_base_m * 1e6) / 1e6;
      out.push_back(serial::encode(f, sequence_++));
      return;
    }
    default:
      return;  // pulses, scans: not on this line
  }
}

bool LineSimulator::write_all(const std::uint8_t* data, std::size_t size, const std::atomic<bool>& stop) {
  // A line nobody reads fills its buffer: the module's writes wait, then the frame is dropped
  // (counted), and a stop is heard between waits.
  for (int waits = 0; size > 0; ++waits) {
    if (!port_.is_open() || stop || waits == 10) {
      ++counts_.dropped_device_gone;
      return false;
    }
    const serial::SerialPort::IoResult r = port_.write(data, size, std::chrono::milliseconds(100));
    if (r.status == serial::SerialPort::Status::kGone) {
      ++counts_.dropped_device_gone;
      return false;
    }
    if (r.status != serial::SerialPort::Status::kData) continue;
    data += r.size;
    size -= r.size;
  }
  return true;
}

void LineSimulator::send(const std::vector<std::uint8_t>& frame, StampNs source_ns, bool sample,
                         const std::atomic<bool>& stop) {
  if (stalled(source_ns)) {
    ++counts_.dropped_in_stall;
    return;
  }
  std::vector<std::uint8_t> bytes = frame;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double step_s = ns_to_s(kStepNs);
  bool intact = true;
  if (options_.corrupt_every_s > 0.0 && unit(random_) < step_s / options_.corrupt_every_s) {
    intact = false;
    // Any byte after the sync: the checksum, the length or the type then says it.
    std::uniform_int_distribution<std::size_t> at(2, bytes.size() - 1);
    bytes[at(random_)] ^= 0x5a;
    ++counts_.corrupted;
  }
  if (options_.garbage_every_s > 0.0 && unit(random_) < step_s / options_.garbage_every_s) {
    std::uniform_int_distribution<int> length(1, 40), byte(0, 255);
    std::vector<std::uint8_t> garbage(static_cast<std::size_t>(length(random_)));
    for (auto& b : garbage) b = static_cast<std::uint8_t>(byte(random_));
    write_all(garbage.data(), garbage.size(), stop);
    ++counts_.garbage_runs;
  }
  if (options_.split_frames && bytes.size() > 2 && !stop) {
    std::uniform_int_distribution<std::size_t> cut(1, bytes.size() - 1);
    const std::size_t at = cut(random_);
    intact = write_all(bytes.data(), at, stop) && intact;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // the gateway reads the first piece alone
    intact = write_all(bytes.data() + at, bytes.size() - at, stop) && intact;
  } else {
    intact = write_all(bytes.data(), bytes.size(), stop) && intact;
  }
  ++counts_.frames;
  if (sample && intact) ++counts_.samples_intact;
}

LineSimulatorCounts LineSimulator::run(const std::atomic<bool>& stop) {
  host_start_ns_ = now_();
  const StampNs end_ns = options_.duration_s > 0.0 ? s_to_ns(options_.duration_s) : -1;
  std::vector<SourceEvent> events;
  std::vector<std::vector<std::uint8_t>> frames;
  StampNs last_sent_ns = 0;
  auto next_reopen = std::chrono::steady_clock::now();
  for (StampNs t = 0; !stop && (end_ns < 0 || t <= end_ns); t += kStepNs) {
    // Real time: source time t goes out at host_start + t.
    const StampNs wait_ns = host_start_ns_ + t - now_();
    if (wait_ns > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait_ns));
    if (!port_.is_open() && std::chrono::steady_clock::now() >= next_reopen) {
      // The device went away (the test's pty pair was torn down): open it again when it is back.
      next_reopen = std::chrono::steady_clock::now() + kReopenPeriod;
      if (port_.open().ok()) ++counts_.reopened;
    }
    events.clear();
    source_.advance(t, events);
    for (const SourceEvent& e : events) {
      if (e.has_truth && truth_.is_open()) {
        truth_ << host_start_ns_ + e.stamp_ns << ',' << e.truth_map_base.x() << ',' << e.truth_map_base.y()
               << ',' << e.truth_map_base.z() << '\n';
      }
      frames.clear();
      frames_of(e, frames);
      for (const auto& f : frames) {
        send(f, e.stamp_ns, true, stop);
        last_sent_ns = t;
      }
    }
    if (t - last_sent_ns >= kHeartbeatNs && options_.protocol == serial::Protocol::kBeaconloc) {
      send(serial::encode(serial::HeartbeatFrame{device_counter(t)}, sequence_++), t, false, stop);
      last_sent_ns = t;
    }
  }
  if (truth_.is_open()) truth_.flush();
  return counts_;
}

}  // namespace beaconloc
