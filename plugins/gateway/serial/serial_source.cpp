#include "serial_source.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {
namespace {

constexpr std::uint64_t kU32Modulus = std::uint64_t{1} << 32;

serial::DeviceClock clock_of(serial::Protocol protocol) {
  // Ours stamps in microseconds, Marvelmind in milliseconds; both count in a u32.
  return protocol == serial::Protocol::kBeaconloc ? serial::DeviceClock(1'000, kU32Modulus)
                                                  : serial::DeviceClock(1'000'000, kU32Modulus);
}

const char* protocol_name(serial::Protocol p) {
  return p == serial::Protocol::kBeaconloc ? "beaconloc serial protocol v1" : "Marvelmind raw distances";
}

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

SerialSource::SerialSource(SerialSourceOptions options, Clock now)
    : options_(std::move(options)),
      now_(std::move(now)),
      started_ns_(now_()),
      port_(options_.device, options_.baud),
      parser_(options_.protocol),
      clock_(clock_of(options_.protocol)) {
  if (options_.receivers.size() == 0) options_.receivers.receivers_base_m.push_back(Eigen::Vector2d::Zero());
  if (!(options_.odometry_k_v_m >= 0.0 && options_.odometry_k_v_m <= 1.0)) {
    throw std::invalid_argument("serial odometry k_v must be in [0, 1] m");
  }
  if (!(options_.odometry_period_s > 0.0 && options_.odometry_period_s <= 1.0)) {
    throw std::invalid_argument("serial odometry period must be in (0, 1] s");
  }
  if (!(std::abs(options_.temperature_c) <= 100.0))
    throw std::invalid_argument("--temperature-c must be in [-100, 100]");
  const serial::SerialPort::OpenResult opened = port_.open();
  // A device not there yet (a USB adapter still enumerating) is waited for; one that is there but
  // cannot be a serial line is a configuration error to tell at once.
  if (!opened.ok() && opened.failure != serial::SerialPort::OpenFailure::kMissing) {
    throw std::runtime_error(opened.message);
  }
  if (!opened.ok()) counts_.reject("serial.device_missing");
  reader_ = std::thread([this] { read_loop(); });
}

SerialSource::~SerialSource() {
  stop_ = true;
  if (reader_.joinable()) reader_.join();
}

std::string SerialSource::describe() const {
  std::ostringstream s;
  s << "serial " << options_.device << " (" << protocol_name(options_.protocol) << ", " << options_.baud
    << " baud)";
  return s.str();
}

void SerialSource::read_loop() {
  std::array<std::uint8_t, 512> buffer{};
  std::vector<serial::Frame> frames;
  // A stall is a line that spoke and stopped: silence before a device's first byte is not one.
  StampNs last_byte_ns = now_();
  bool spoken = false, stalled = false;
  while (!stop_) {
    if (!port_.is_open()) {
      std::this_thread::sleep_for(kReopenPeriod);
      if (stop_) break;
      const serial::SerialPort::OpenResult opened = port_.open();
      if (!opened.ok()) {
        // Once per absence: a device back with the wrong permissions (udev not done yet) or held
        // by another program is told; one simply not there yet is device_gone's.
        if (!reopen_failure_counted_ && opened.failure != serial::SerialPort::OpenFailure::kMissing) {
          std::lock_guard<std::mutex> lock(mutex_);
          counts_.reject("serial.reopen_failed");
          reopen_failure_counted_ = true;
        }
        continue;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      counts_.reject("serial.reopened");  // counted as the line's event, not a sample refused
      spoken = stalled = false;
    }
    const serial::SerialPort::IoResult r =
        port_.read(buffer.data(), buffer.size(), std::chrono::milliseconds(50));
    const StampNs arrival_ns = now_();
    std::lock_guard<std::mutex> lock(mutex_);
    if (r.status == serial::SerialPort::Status::kGone) {
      counts_.reject("serial.device_gone");
      parser_.reset_partial();  // a frame cut by the unplug is counted truncated
      clock_.reset();           // the device that comes back may be another, its counter restarted
      previous_odometry_ns_ = -1;
      reopen_failure_counted_ = false;
      continue;
    }
    if (r.status != serial::SerialPort::Status::kData) {
      if (spoken && !stalled && arrival_ns - last_byte_ns > kStalledNs) {
        counts_.reject("serial.stalled");
        stalled = true;
      }
      continue;
    }
    last_byte_ns = arrival_ns;
    spoken = true;
    stalled = false;
    frames.clear();
    parser_.push(buffer.data(), r.size, arrival_ns, frames);
    for (const auto& f : frames) convert(f);
  }
}

void SerialSource::convert(const serial::Frame& frame) {
  std::visit(
      Overloaded{
          [&](const serial::TofFrame& t) {
            const StampNs fire_ns = clock_.map(t.fire_time_us, frame.arrival_ns);
            add_tof(fire_ns, static_cast<double>(t.tof_ns) * 1e-9, t.beacon_id, t.receiver_id,
                    t.has_temperature ? t.temperature_c : options_.temperature_c);
          },
          [&](const serial::OdometryFrame& o) {
            const StampNs stamp_ns = clock_.map(o.stamp_us, frame.arrival_ns);
            if (clock_.counts().clock_resets != clock_resets_seen_) {
              clock_resets_seen_ = clock_.counts().clock_resets;  // a new time line: no dT across it
              previous_odometry_ns_ = -1;
            }
            const double dt_s = previous_odometry_ns_ < 0 ? options_.odometry_period_s
                                                          : ns_to_s(stamp_ns - previous_odometry_ns_);
            if (!(dt_s > 0.0)) {
              // Not after the frame before it: no interval for the noise model, and no new sample.
              counts_.reject("serial.odometry_not_after_previous");
              return;
            }
            previous_odometry_ns_ = stamp_ns;
            SourceEvent e;
            e.kind = SourceEvent::Kind::kOdometry;
            e.stamp_ns = stamp_ns;
            e.odometry.stamp_ns = stamp_ns;
            e.odometry.wheel_velocity_right_mps = o.right_mps;
            e.odometry.wheel_velocity_left_mps = o.left_mps;
            e.odometry.wheel_base_m = o.wheel_base_m;
            const Eigen::Vector2d speeds(std::abs(o.right_mps), std::abs(o.left_mps));
            e.odometry.wheel_velocity_covariance = (options_.odometry_k_v_m * speeds / dt_s).asDiagonal();
            push(e);
          },
          [&](const serial::HeartbeatFrame& h) { clock_.map(h.stamp_us, frame.arrival_ns); },
          [&](const serial::DistancesFrame& d) {
            const StampNs measured_ns = clock_.map(d.stamp_ms, frame.arrival_ns);
            const double c = speed_of_sound_mps(options_.temperature_c);
            for (const auto& slot : d.slots) {
              const double tof_s = static_cast<double>(slot.distance_mm) * 1e-3 / c;
              add_tof(measured_ns - s_to_ns(tof_s), tof_s, slot.beacon_address, 0, options_.temperature_c);
            }
          },
      },
      frame.body);
}

void SerialSource::push(const SourceEvent& e) {
  // A gateway that stopped taking must not make the reader grow without bound: beyond
  // kMaxPending the oldest go, counted.
  if (pending_.size() >= kMaxPending) {
    pending_.pop_front();
    counts_.reject("serial.backlog_dropped");
  }
  pending_.push_back(e);
}

void SerialSource::add_tof(StampNs fire_ns, double tof_s, std::uint32_t beacon_id, std::uint32_t receiver_id,
                           double temperature_c) {
  SourceEvent e;
  e.kind = SourceEvent::Kind::kTof;
  e.tof.fire_stamp_ns = fire_ns;
  e.tof.tof_s = tof_s;
  e.tof.beacon_id = beacon_id;
  e.tof.receiver_id = receiver_id;
  e.tof.beacon_temperature_c = temperature_c;
  e.tof.sequence_number = sequence_++;
  e.stamp_ns = fire_ns + s_to_ns(tof_s);
  push(e);
}

void SerialSource::advance(StampNs /*until_ns*/, std::vector<SourceEvent>& out) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Live: what has arrived goes out at once, in stamp order among itself. The gateway's step time
  // is not the frames' clock (it starts when the gateway does, and a host clock that steps moves
  // the frames' stamps, not it): holding frames back by it would only delay them.
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const SourceEvent& a, const SourceEvent& b) { return a.stamp_ns < b.stamp_ns; });
  out.insert(out.end(), pending_.begin(), pending_.end());
  pending_.clear();
}

RejectionCounter SerialSource::input_rejections() const {
  std::lock_guard<std::mutex> lock(mutex_);
  RejectionCounter c = counts_;
  const serial::FrameParser::Counts& p = parser_.counts();
  for (std::size_t i = 0; i < serial::kFrameRejectionCount; ++i) {
    c.reject(std::string("serial.") + to_string(static_cast<serial::FrameRejection>(i)), p.rejected[i]);
  }
  c.reject("serial.frames_lost", p.frames_lost);
  c.reject("serial.garbage_bytes", p.garbage_bytes);
  c.reject("serial.clock_resets", clock_.counts().clock_resets);
  return c;
}

}  // namespace beaconloc
