#include "gateway_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

GatewayParticipant::GatewayParticipant(const dds::DdsOptions& dds, GatewayOptions options,
                                       std::unique_ptr<Source> source, TruthCallback on_truth,
                                       Throttle throttle)
    : options_(std::move(options)),
      source_(std::move(source)),
      on_truth_(std::move(on_truth)),
      throttle_(std::move(throttle)),
      participant_(dds, "beaconloc.gateway." + options_.robot_id),
      map_writer_(participant_.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, &map_readers_)),
      // The robot's measurements, in its partition (a gateway's permissions grant it no other).
      tof_writer_(participant_.robot_writer<msg::RawTofPubSubType>(dds::kRawTofTopic, options_.robot_id)),
      pulse_writer_(participant_.robot_writer<msg::PulseArrivalPubSubType>(dds::kPulseArrivalTopic, options_.robot_id)),
      odometry_writer_(participant_.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, options_.robot_id)),
      scan_writer_(participant_.robot_writer<msg::LaserScanPubSubType>(dds::kLaserScanTopic, options_.robot_id)) {
  if (source_->honours_firing_plan()) {
    const std::vector<std::uint32_t> every = fire_all(source_->beacon_map());
    scheduler_.emplace(source_->slot_period_ns(), std::set<std::uint32_t>(every.begin(), every.end()));
  }
  if (!(options_.speed == 0.0 ||
        (options_.speed >= GatewayOptions::kMinSpeed && options_.speed <= GatewayOptions::kMaxSpeed))) {
    std::ostringstream why;
    why << "--speed must be 0 (as fast as it goes) or within [" << GatewayOptions::kMinSpeed << ", "
        << GatewayOptions::kMaxSpeed << "], got " << options_.speed;
    throw std::invalid_argument(why.str());
  }
  if (!(options_.duration_s >= 0.0)) throw std::invalid_argument("--duration-s must be >= 0");
  if (options_.wait_for_readers < 0 || options_.wait_for_readers > GatewayOptions::kMaxWaitForReaders) {
    throw std::invalid_argument("--wait-for-readers must be in [0, " +
                                std::to_string(GatewayOptions::kMaxWaitForReaders) + "]");
  }
  if (!options_.truth_csv.empty()) {
    truth_.open(options_.truth_csv);
    if (!truth_) throw std::runtime_error("cannot write truth file '" + options_.truth_csv + "'");
    truth_ << "stamp_ns,x_m,y_m,yaw_rad\n" << std::setprecision(10);
  }
  if (!options_.record_dir.empty()) {
    constexpr bool kWithHiddenTruth = true;
    record_.emplace(options_.record_dir, kWithHiddenTruth);
    record_->write_receivers(source_->receivers());
  }
  const double source_s = ns_to_s(source_->last_stamp_ns() - source_->first_stamp_ns());
  total_s_ = options_.duration_s > 0.0 ? options_.duration_s : source_s;
  // raw_tof and odometry liveliness is manual by topic (examples/qos/topics.xml): this process
  // asserts it every 250 ms (lease 1 s), so readers notice a gateway that dies, while one that
  // hears no beacon, waits for a slow pipeline or replays a gap in a recording stays alive.
  liveliness_ = std::make_unique<dds::PeriodicTask>(std::chrono::milliseconds(250), [this] {
    tof_writer_->assert_liveliness();
    pulse_writer_->assert_liveliness();
    odometry_writer_->assert_liveliness();
    repeat_map_after_match();
  });
  if (!options_.firings_csv.empty()) {
    firings_.open(options_.firings_csv);
    if (!firings_) throw std::runtime_error("cannot write firings file '" + options_.firings_csv + "'");
    firings_ << "fire_stamp_ns,beacon_id,planned,heard\n";
  }
  plan_reader_ = participant_.subscribe<msg::FiringPlanPubSubType>(dds::kFiringPlanTopic, [this](const msg::FiringPlan& m) {
    if (m.robot_id() != options_.robot_id) return;  // another robot's gateway fires by it
    const StampNs now_ns = now_stamp_ns_.load();
    if (now_ns < 0) return;  // not running yet: no plan can be for its samples
    std::lock_guard<std::mutex> lock(plan_mutex_);
    if (scheduler_) {
      scheduler_->take(m.beacon_ids(), m.stamp_ns(), now_ns);
    } else {
      ++plans_ignored_;  // not a fault of the plan: said in the Diagnostics message
    }
  });
  diagnostics_ = std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] {
    RejectionCounter counts;
    {
      std::lock_guard<std::mutex> lock(counts_mutex_);
      counts = counts_;
    }
    counts.add_rejections(source_->input_rejections(), "source.");
    const std::string firing = firing_summary();
    {
      std::lock_guard<std::mutex> lock(plan_mutex_);
      if (scheduler_) {
        for (const auto& [refusal, n] : scheduler_->refusals()) {
          counts.reject(std::string("firing_plan.") + to_string(refusal), n);
        }
      }
    }
    return dds::make_diagnostics(
        participant_.name(), dds::wall_clock_ns(), counts, 0,
        counts.rejected_total() ? msg::PARTICIPANT_STATUS_DEGRADED : msg::PARTICIPANT_STATUS_OK,
        source_->describe() + ", robot " + options_.robot_id + firing);
  });
}

GatewayParticipant::~GatewayParticipant() {
  stop();  // joins the run thread: a std::thread must not be destroyed running
}

bool GatewayParticipant::wait_for_readers(std::chrono::milliseconds timeout) const {
  const bool pulses = source_->beacon_input() == BeaconInput::kPulseArrivals;
  return dds::wait_for_matched_readers({pulses ? pulse_writer_ : tof_writer_, odometry_writer_}, timeout);
}

bool GatewayParticipant::wait_for_readers_before_start() {
  const bool pulses = source_->beacon_input() == BeaconInput::kPulseArrivals;
  const auto matched = [](const dds::Writer& w) {
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    w->get_publication_matched_status(status);
    return status.current_count;
  };
  for (;;) {
    if (matched(pulses ? pulse_writer_ : tof_writer_) >= options_.own_beacon_readers + options_.wait_for_readers &&
        matched(odometry_writer_) >= options_.own_odometry_readers + options_.wait_for_readers) {
      return true;
    }
    std::unique_lock<std::mutex> lock(stop_mutex_);
    if (stop_cv_.wait_for(lock, std::chrono::milliseconds(10), [this] { return stop_.load(); })) return false;
  }
}

void GatewayParticipant::start() {
  thread_ = std::thread([this] { run(); });
}

void GatewayParticipant::stop() {
  {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void GatewayParticipant::rethrow_failure() const {
  if (!failure_.empty()) throw std::runtime_error(failure_);
}

void GatewayParticipant::repeat_map_after_match() {
  if (!map_written_.load(std::memory_order_acquire)) return;
  const StampNs match_ns = map_readers_.newest_match_ns.load();
  if (match_ns == 0) return;
  if (match_ns != map_repeat_match_ns_) {
    map_repeat_match_ns_ = match_ns;
    map_repeats_ = 0;
  }
  // Once a second for kMapRepeats seconds after the newest match.
  if (map_repeats_ == kMapRepeats ||
      dds::steady_clock_ns() - match_ns < static_cast<StampNs>(map_repeats_ + 1) * kNsPerSecond) {
    return;
  }
  ++map_repeats_;
  if (!map_writer_->write(&map_msg_)) count(false);  // the same map: not a new sample
}

void GatewayParticipant::count(bool written) {
  std::lock_guard<std::mutex> lock(counts_mutex_);
  if (written) {
    counts_.accept();
  } else {
    counts_.reject("write_failed");
  }
}

template <class Write>
void GatewayParticipant::record(Write&& write) {
  if (!record_) return;
  try {
    write();
  } catch (const std::runtime_error& e) {
    // A full disk, say: the run goes on without its recording, and fails at the end saying why.
    failure_ = e.what();
    record_.reset();
  }
}

void GatewayParticipant::publish(SourceEvent& e, StampNs offset_ns) {
  const StampNs stamp = e.stamp_ns + offset_ns;
  if (e.has_truth) {
    if (truth_.is_open()) {
      truth_ << stamp << ',' << e.truth_map_base.x() << ',' << e.truth_map_base.y() << ',';
      if (e.truth_has_yaw) truth_ << e.truth_map_base.z();
      truth_ << '\n';
    }
    if (on_truth_) on_truth_(stamp, e.truth_map_base, e.truth_has_yaw);
  }
  switch (e.kind) {
    case SourceEvent::Kind::kTof: {
      e.tof.fire_stamp_ns += offset_ns;
      record([&] { record_->write(e.tof, {e.true_beacon_id, e.tof_is_echo}); });
      auto m = dds::to_msg(options_.robot_id, e.tof);
      count(tof_writer_->write(&m));  // bool in Fast DDS 2.9 (TOOLCHAIN.md)
      ++progress_.tofs_written;
      break;
    }
    case SourceEvent::Kind::kPulse: {
      e.pulse.stamp_ns = stamp;
      record([&] { record_->write(e.pulse, {e.true_beacon_id, e.tof_is_echo}); });
      auto m = dds::to_msg(options_.robot_id, e.pulse);
      count(pulse_writer_->write(&m));
      ++progress_.tofs_written;
      break;
    }
    case SourceEvent::Kind::kOdometry: {
      e.odometry.stamp_ns = stamp;
      record([&] { record_->write(e.odometry); });
      auto m = dds::to_msg(options_.robot_id, e.odometry, odometry_sequence_++);
      count(odometry_writer_->write(&m));
      ++progress_.odometry_written;
      break;
    }
    case SourceEvent::Kind::kLaserScan: {
      e.scan.stamp_ns = stamp;
      record([&] { record_->write(e.scan); });
      auto m = dds::to_msg(options_.robot_id, e.scan);
      count(scan_writer_->write(&m));
      break;
    }
    case SourceEvent::Kind::kTruth:
      break;
  }
  progress_.newest_stamp_ns = stamp;
}

std::string GatewayParticipant::firing_summary() {
  std::lock_guard<std::mutex> lock(plan_mutex_);
  if (!scheduler_) {
    return plans_ignored_ ? ", " + std::to_string(plans_ignored_) + " firing plans ignored (the source fires what it recorded)"
                          : "";
  }
  return std::string(scheduler_->following_plan() ? ", firing by plan" : ", firing every beacon") + " (" +
         std::to_string(scheduler_->plans_taken()) + " plans, " + std::to_string(scheduler_->stale_fallbacks()) +
         " fallbacks on stale plans, " + std::to_string(scheduler_->unheard_fallbacks()) +
         " on unheard planned firings; " + std::to_string(firings_planned_) + " firings by plan, " +
         std::to_string(firings_every_) + " of every beacon)";
}

void GatewayParticipant::apply_firing_plan(StampNs now_stamp_ns) {
  now_stamp_ns_ = now_stamp_ns;
  if (!scheduler_) return;
  std::optional<std::vector<std::uint32_t>> plan;
  {
    std::lock_guard<std::mutex> lock(plan_mutex_);
    plan = scheduler_->plan_at(now_stamp_ns);
  }
  source_->set_firing_plan(std::move(plan));
}

void GatewayParticipant::log_firings(StampNs offset_ns) {
  const std::vector<Source::Firing> firings = source_->take_firings();
  if (firings.empty()) return;
  {
    std::lock_guard<std::mutex> lock(plan_mutex_);
    for (const Source::Firing& f : firings) {
      (f.planned ? firings_planned_ : firings_every_) += 1;
      if (scheduler_) scheduler_->on_firing(f.planned, f.heard);
    }
  }
  if (!firings_.is_open()) return;
  for (const Source::Firing& f : firings) {
    firings_ << f.fire_stamp_ns + offset_ns << ',' << f.beacon_id << ',' << f.planned << ',' << f.heard << '\n';
  }
}

void GatewayParticipant::run() {
  using clock = std::chrono::steady_clock;
  // Simulated stamps start at 0: offset them to the wall clock at start, so live consumers see
  // real times. A recording keeps its own clock.
  const StampNs offset_ns =
      source_->relative_stamps() && options_.wall_clock_stamps ? dds::wall_clock_ns() : 0;
  map_msg_ = dds::to_msg(source_->beacon_map(), options_.frame_id);
  count(map_writer_->write(&map_msg_));
  map_written_.store(true, std::memory_order_release);
  if (throttle_) throttle_();  // before the first sample: the map may be waited for
  if (options_.wait_for_readers > 0 && !wait_for_readers_before_start()) {
    finished_ = true;
    return;
  }

  std::vector<SourceEvent> events;
  const StampNs step_ns = 10 * kNsPerMillisecond;
  const StampNs begin_ns = source_->first_stamp_ns();
  // With a duration: that much source time. Without: a recording to its end, a simulation
  // until stopped.
  const bool bounded = options_.duration_s > 0.0 || source_->finite();
  const StampNs last_ns =
      options_.duration_s > 0.0 ? begin_ns + s_to_ns(options_.duration_s) : source_->last_stamp_ns();
  const auto wall_start = clock::now();
  for (StampNs t_ns = begin_ns; !stop_ && !(bounded && t_ns - step_ns >= last_ns); t_ns += step_ns) {
    events.clear();
    apply_firing_plan(std::max<StampNs>(0, t_ns - step_ns + offset_ns));
    source_->advance(bounded ? std::min(t_ns, last_ns) : t_ns, events);
    log_firings(offset_ns);
    if (options_.speed > 0.0) {
      // Capped at 30 years of waiting (a recording of absurd length at the slowest speed), so
      // that the offset is a representable time whatever the stamps.
      const double wait_s = std::min(ns_to_s(t_ns - begin_ns) / options_.speed, 1e9);
      const auto wall_offset =
          std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(wait_s));
      std::unique_lock<std::mutex> lock(stop_mutex_);
      if (stop_cv_.wait_until(lock, wall_start + wall_offset, [this] { return stop_.load(); })) break;
    }
    for (auto& e : events) publish(e, offset_ns);
    elapsed_s_ = ns_to_s(std::min(t_ns, bounded ? last_ns : t_ns) - begin_ns);
    if (throttle_) throttle_();
    if (source_->exhausted()) break;
  }
  for (auto* file : {&truth_, &firings_}) {
    if (file->is_open() && !file->flush()) failure_ = "writing the gateway's output files failed";
  }
  diagnostics_->publish_now();
  finished_ = true;
}

}  // namespace beaconloc
