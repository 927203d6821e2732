#include "gateway_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <chrono>
#include <iomanip>
#include <stdexcept>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc {

GatewayParticipant::GatewayParticipant(const dds::DdsOptions& dds, GatewayOptions options,
                                       sim::Scenario scenario, TruthCallback on_truth)
    : options_(std::move(options)),
      scenario_(std::move(scenario)),
      on_truth_(std::move(on_truth)),
      participant_(dds, "beaconloc.gateway." + options_.robot_id),
      map_writer_(participant_.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic)),
      tof_writer_(participant_.writer<msg::RawTofPubSubType>(dds::kRawTofTopic)),
      odometry_writer_(participant_.writer<msg::OdometryPubSubType>(dds::kOdometryTopic)) {
  if (!(options_.speed > 0.0)) throw std::invalid_argument("--speed must be > 0");
  if (options_.duration_s < 0.0) throw std::invalid_argument("--duration-s must be >= 0");
  if (!options_.truth_csv.empty()) {
    truth_.open(options_.truth_csv);
    if (!truth_) throw std::runtime_error("cannot write truth file '" + options_.truth_csv + "'");
    truth_ << "stamp_ns,x_m,y_m,yaw_rad\n" << std::setprecision(10);
  }
  diagnostics_ = std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] {
    std::lock_guard<std::mutex> lock(counts_mutex_);
    return dds::make_diagnostics(
        participant_.name(), dds::wall_clock_ns(), counts_, 0,
        counts_.rejected_total() ? msg::PARTICIPANT_STATUS_DEGRADED : msg::PARTICIPANT_STATUS_OK,
        "simulated source, robot " + options_.robot_id);
  });
}

GatewayParticipant::~GatewayParticipant() {
  stop();
  diagnostics_->stop();
  participant_.close();
}

void GatewayParticipant::start() {
  thread_ = std::thread([this] { run(); });
}

void GatewayParticipant::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void GatewayParticipant::rethrow_failure() const {
  if (!failure_.empty()) throw std::runtime_error(failure_);
}

void GatewayParticipant::count(bool written) {
  std::lock_guard<std::mutex> lock(counts_mutex_);
  if (written) {
    counts_.accept();
  } else {
    counts_.reject("write_failed");
  }
}

void GatewayParticipant::run() {
  using clock = std::chrono::steady_clock;
  // Sim stamps are offset to the wall clock at start, so live consumers see real times.
  const StampNs epoch_ns = dds::wall_clock_ns();
  auto beacon_map = dds::to_msg(BeaconMap(scenario_.beacons), options_.frame_id);
  map_writer_->write(&beacon_map);

  sim::SimSource source(scenario_, options_.seed);
  std::vector<sim::SimEvent> events;
  const StampNs step_ns = scenario_.odometry_period_ns;
  const StampNs end_ns = options_.duration_s > 0.0 ? s_to_ns(options_.duration_s) : -1;
  const auto wall_start = clock::now();
  std::uint64_t odometry_sequence = 0;
  for (StampNs sim_ns = step_ns; !stop_ && (end_ns < 0 || sim_ns <= end_ns); sim_ns += step_ns) {
    events.clear();
    source.advance(sim_ns, events);
    std::this_thread::sleep_until(wall_start + std::chrono::nanoseconds(static_cast<StampNs>(
                                                   static_cast<double>(sim_ns) / options_.speed)));
    for (auto& e : events) {
      bool written = false;
      if (e.kind == sim::SimEvent::Kind::kTof) {
        e.tof.fire_stamp_ns += epoch_ns;
        auto m = dds::to_msg(options_.robot_id, e.tof);
        written = tof_writer_->write(&m);  // bool in Fast DDS 2.9 (TOOLCHAIN.md)
      } else {
        e.odometry.stamp_ns += epoch_ns;
        auto m = dds::to_msg(options_.robot_id, e.odometry, odometry_sequence++);
        written = odometry_writer_->write(&m);
        const StampNs stamp = e.odometry.stamp_ns;
        if (truth_) {
          truth_ << stamp << ',' << e.truth_map_base.x() << ',' << e.truth_map_base.y() << ','
                 << e.truth_map_base.z() << '\n';
        }
        if (on_truth_) on_truth_(stamp, e.truth_map_base);
      }
      count(written);
    }
  }
  if (truth_) {
    truth_.flush();
    if (!truth_) failure_ = "writing truth file '" + options_.truth_csv + "' failed";
  }
  diagnostics_->publish_now();
  finished_ = true;
}

}  // namespace beaconloc
