#include "localizer_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "beaconloc/core/calibration_store.hpp"
#include "beaconloc/core/firing_plan.hpp"
#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

template <class PubSubType, class Fuse>
void LocalizerParticipant::subscribe_beacon_measurements(const dds::TopicSpec& topic, Fuse fuse) {
  using Msg = typename PubSubType::type;
  dds::ReaderEvents<Msg> events;
  events.deadline_misses = &deadline_misses_;
  events.writers_lost = &range_writers_lost_;
  events.lost_and_none_alive = &range_writer_lost_;
  events.on_deadline_missed = [this](const Msg& key) {
    std::lock_guard<std::mutex> lock(mutex_);
    core_.on_ranges_silent(key.robot_id());
  };
  readers_.push_back(participant_.subscribe<PubSubType>(
      topic,
      [this, fuse](const Msg& m) {
        {
          // Written under the lock, as every pose is, so that a robot's poses go out in stamp
          // order: a correction at once, not with the next odometry sample.
          std::lock_guard<std::mutex> lock(mutex_);
          if (serves(m.robot_id())) {
            if (auto corrected = fuse(m)) publish(*corrected);
            share_calibration();
          }
        }
        ++ranges_processed_;
      },
      events));
}

namespace {
// The calibration kept in the file, if any; throws CalibrationFileError for a file that exists
// and cannot be used (nothing is guessed from a damaged file).
std::optional<BeaconCalibration> kept_calibration(const std::string& path) {
  if (path.empty()) return std::nullopt;
  CalibrationFileResult result;
  std::optional<BeaconCalibration> kept = load_calibration(path, &result);
  if (result.problem == CalibrationFileProblem::kMissing) return std::nullopt;  // none kept yet
  if (!kept) {
    throw CalibrationFileError("calibration file " + path + ": " + to_string(result.problem) + ": " + result.detail);
  }
  return kept;
}

// A shard's participant name tells the shards apart in the Diagnostics (the monitor, a peer's
// serving conflicts): the host and the process.
std::string participant_name(const std::string& estimator, bool shard) {
  std::string name = "beaconloc.localizer." + estimator;
  if (!shard) return name;
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  return name + ".shard." + (host[0] ? host : "unknown-host") + "." + std::to_string(getpid());
}

// How often a shard asserts its announcement's liveliness: five times a lease (topics.xml), so
// that a shard stalled for most of a lease by a busy machine keeps its robots.
constexpr StampNs kShardAssertionsPerLease = 5;
// The longest estimator or participant name an announcement may carry (ours are under 100).
constexpr std::size_t kMaxShardTextLength = 256;
}  // namespace

LocalizerParticipant::LocalizerParticipant(const dds::DdsOptions& dds, LocalizerCore core,
                                           LocalizerParticipantOptions options)
    : core_(std::move(core)),
      conflicts_(std::chrono::duration_cast<std::chrono::nanoseconds>(dds::kDiagnosticsSilentAfter).count()),
      options_(std::move(options)),
      participant_(dds, participant_name(core_.estimator_name(), options_.shard)),
      pose_writer_(participant_.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic)),
      state_writer_(participant_.writer<msg::EstimatorStatePubSubType>(dds::kEstimatorStateTopic)),
      calibration_writer_(participant_.writer<msg::BeaconCalibrationPubSubType>(dds::kBeaconCalibrationTopic)),
      plan_writer_(options_.selective_activation ? participant_.writer<msg::FiringPlanPubSubType>(dds::kFiringPlanTopic)
                                                 : dds::Writer()) {
  own_calibration_writer_ = dds::writer_id(calibration_writer_->get_instance_handle());
  if (options_.shard) announce_shard();  // its membership before the first sample, which it may not serve
  if (!options_.calibration_file.empty() && !core_.uses_calibration()) {
    throw CalibrationFileError("calibration file " + options_.calibration_file + ": the estimator " +
                               core_.estimator_name() + " uses no beacon calibration");
  }
  if (const std::optional<BeaconCalibration> kept = kept_calibration(options_.calibration_file)) {
    core_.on_calibration(*kept);
    calibration_shared_revision_ = core_.calibration_revision();  // in the file already
    auto m = dds::to_msg(core_.calibration(), map_frame_id_);
    calibration_writer_->write(&m);
  }
  // Every writer's map is remembered: two live gateways with different maps are reported.
  dds::ReaderEvents<msg::BeaconMap> map_events;
  map_events.on_writer_gone = [this](const std::string& writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    map_sources_.on_writer_gone(writer);
    // The writers left agree: their map is the site's, whichever arrived last before.
    if (const auto agreed = map_sources_.agreed_map(); agreed && !(*agreed == core_.beacon_map())) {
      core_.set_beacon_map(*agreed);
      share_calibration();
    }
  };
  map_reader_ = std::make_unique<dds::FirstSampleWatch>([this, map_events](std::function<void()> heard) {
    return participant_.subscribe_with_info<msg::BeaconMapPubSubType>(
        dds::kBeaconMapTopic,
        [this, heard](const msg::BeaconMap& m, const eprosima::fastdds::dds::SampleInfo& info) {
          heard();
          std::lock_guard<std::mutex> lock(mutex_);
          if (core_.on_beacon_map(dds::from_msg(m))) {
            map_sources_.on_map(dds::writer_id(info.publication_handle), core_.beacon_map());
            map_frame_id_ = m.frame_id();
            share_calibration();  // a new map drops the groups it does not hold
          }
        },
        map_events);
  }, [this] { return odometry_processed_.load() + ranges_processed_.load() > 0; });  // a gateway heard
  // Other localizers' calibrations (its own comes back too: not news). Each sample is a site's
  // whole calibration; its groups replace the ones held (LocalizerCore::on_calibration).
  readers_.push_back(participant_.subscribe_with_info<msg::BeaconCalibrationPubSubType>(
      dds::kBeaconCalibrationTopic,
      [this](const msg::BeaconCalibration& m, const eprosima::fastdds::dds::SampleInfo& info) {
        // Before the lock: Fast DDS may hand its own sample back on the writing thread, which
        // holds mutex_ (share_calibration).
        if (dds::writer_id(info.publication_handle) == own_calibration_writer_) return;
        std::lock_guard<std::mutex> lock(mutex_);
        std::size_t beacons = 0;
        for (const msg::GroupCalibration& g : m.groups()) beacons += g.beacons().size();
        if (m.groups().size() > kMaxBeacons || beacons > kMaxBeacons) {
          ++calibrations_refused_too_large_;  // not even converted: no site has that many
          return;
        }
        if (m.frame_id() != map_frame_id_) {
          ++calibrations_refused_other_frame_;  // positions in a frame that is not the map's
          return;
        }
        core_.on_calibration(dds::from_msg(m));
        share_calibration();
      }));
  // The beacon measurements, as the estimator hears them (beacon_input): the decoder's ranges,
  // the gateway's raw TOFs, or its pulse arrivals (seed 002); never two kinds. A robot whose measurements miss their deadline (two beacon slots) coasts on odometry,
  // degraded; a writer that dies or hangs (liveliness, lease 1 s) is reported, not only felt as
  // silence.
  switch (core_.beacon_input()) {
    case BeaconInput::kRawTof:
      subscribe_beacon_measurements<msg::RawTofPubSubType>(dds::kRawTofTopic, [this](const msg::RawTof& m) {
        return core_.on_raw_tof(m.robot_id(), dds::from_msg(m));
      });
      break;
    case BeaconInput::kPulseArrivals:
      subscribe_beacon_measurements<msg::PulseArrivalPubSubType>(
          dds::kPulseArrivalTopic,
          [this](const msg::PulseArrival& m) { return core_.on_pulse(m.robot_id(), dds::from_msg(m)); });
      break;
    case BeaconInput::kRanges:
      subscribe_beacon_measurements<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic, [this](const msg::BeaconRange& m) {
        return core_.on_range(m.robot_id(), dds::from_msg(m));
      });
      break;
  }
  // The gateway's odometry writer: liveliness tells a dead gateway from a robot standing still.
  dds::ReaderEvents<msg::Odometry> odometry_events;
  odometry_events.deadline_misses = &deadline_misses_;
  odometry_events.writers_lost = &odometry_writers_lost_;
  odometry_events.lost_and_none_alive = &odometry_writer_lost_;
  // A gateway that stopped or hung (its liveliness is asserted by a task of its own, so a hung run
  // loop still looks alive) shows as missed deadlines: past a few in a row the robot is degraded
  // until odometry flows again (LocalizerCore::kOdometrySilentAfterMisses).
  odometry_events.on_deadline_missed = [this](const msg::Odometry& key) {
    std::lock_guard<std::mutex> lock(mutex_);
    core_.on_odometry_deadline_missed(key.robot_id());
  };
  readers_.push_back(participant_.subscribe<msg::OdometryPubSubType>(
      dds::kOdometryTopic, [this](const msg::Odometry& m) { on_odometry(m); }, odometry_events));
  if (core_.uses_laser()) {
    readers_.push_back(participant_.subscribe<msg::LaserScanPubSubType>(dds::kLaserScanTopic, [this](const msg::LaserScan& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!serves(m.robot_id())) return;
      if (auto corrected = core_.on_laser(m.robot_id(), dds::from_msg(m))) publish(*corrected);
      share_calibration();
    }));
  }
  readers_.push_back(participant_.subscribe<msg::InitialPosePubSubType>(
      dds::kInitialPoseTopic, [this](const msg::InitialPose& m) {
        Cov3 c;
        for (int i = 0; i < 9; ++i) c(i / 3, i % 3) = m.covariance()[static_cast<std::size_t>(i)];
        std::lock_guard<std::mutex> lock(mutex_);
        if (!serves(m.robot_id())) return;
        core_.on_initial_pose(m.robot_id(), m.stamp_ns(), Pose2(m.x_m(), m.y_m(), m.yaw_rad()), c);
      }));
  diagnostics_ =
      std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] { return diagnostics_snapshot(); });
  own_diagnostics_writer_ = diagnostics_->writer();
  // The other localizers' reports (1 Hz each): which robots they serve, and when they leave.
  dds::ReaderEvents<msg::Diagnostics> peer_events;
  peer_events.on_writer_gone = [this](const std::string& writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    conflicts_.on_peer_gone(writer, dds::steady_clock_ns());
  };
  peer_events.on_instance_ended = [this](const eprosima::fastdds::dds::SampleInfo& info) {
    std::lock_guard<std::mutex> lock(mutex_);
    conflicts_.on_peer_gone(dds::writer_id(info.publication_handle), dds::steady_clock_ns());
  };
  readers_.push_back(participant_.subscribe_with_info<msg::DiagnosticsPubSubType>(
      dds::kDiagnosticsTopic,
      [this](const msg::Diagnostics& d, const eprosima::fastdds::dds::SampleInfo& info) {
        on_peer_diagnostics(d, dds::writer_id(info.publication_handle));
      },
      peer_events));
  if (options_.shard) listen_to_shards();  // after diagnostics_, which a change of shards publishes
}

bool LocalizerParticipant::serves(const std::string& robot_id) {
  if (!shard_) return true;
  const StampNs now_ns = dds::steady_clock_ns();
  check_shard_stall(now_ns);
  // Serves once alive to the others (its first assertion after settling), not a tick before.
  if (shard_asserted_ns_ && shard_->serves(robot_id, now_ns)) return true;
  ++other_shard_samples_;
  return false;
}

void LocalizerParticipant::announce_shard() {
  shard_writer_ = participant_.writer<msg::LocalizerShardPubSubType>(dds::kLocalizerShardTopic, &shard_matches_);
  const eprosima::fastdds::dds::LivelinessQosPolicy liveliness = shard_writer_->get_qos().liveliness();
  if (liveliness.kind != eprosima::fastdds::dds::MANUAL_BY_TOPIC_LIVELINESS_QOS ||
      liveliness.lease_duration == eprosima::fastrtps::c_TimeInfinite) {
    // Without a finite lease asserted by this localizer, a dead or hung shard would keep its
    // robots for good: the profile was edited, refuse to start.
    throw dds::DdsError("profile localizer_shard.writer: a shard needs manual-by-topic liveliness with a finite lease");
  }
  shard_lease_ns_ = static_cast<StampNs>(liveliness.lease_duration.seconds) * kNsPerSecond +
                    static_cast<StampNs>(liveliness.lease_duration.nanosec);
  shard_.emplace(dds::writer_id(shard_writer_->get_instance_handle()), core_.estimator_name(), kShardSettleNs);
}

void LocalizerParticipant::listen_to_shards() {
  // Each event under the lock; a change of the live shards hands robots over at once and says so
  // in the Diagnostics at once, so that the shard taking a robot over does not see it listed by
  // this one for up to a period (a serving conflict).
  auto changed = [this](auto change) {
    bool moved = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const bool stalled = check_shard_stall(dds::steady_clock_ns());  // robots from before a stall go first
      moved = change();
      if (moved) release_robots_not_served();
      moved = moved || stalled;
    }
    if (moved) diagnostics_->publish_now();
  };
  dds::ReaderEvents<msg::LocalizerShard> events;
  events.on_writer_gone = [this, changed](const std::string& writer) {
    changed([&] {
      const bool moved = shard_->on_shard_lost(writer);
      // Its Diagnostics may go on listing its robots for seconds (a killed process's last report):
      // not a conflict with the shard taking them over.
      if (moved) conflicts_.on_peers_gone(dds::participant_of_writer(writer), dds::steady_clock_ns());
      return moved;
    });
  };
  events.on_writer_alive = [this, changed](const std::string& writer) {
    changed([&] { return shard_->on_shard_alive(writer); });
  };
  events.on_writer_unmatched = [this, changed](const std::string& writer) {
    changed([&] { return shard_->on_shard_gone(writer); });  // a restarted shard comes with a new id
  };
  readers_.push_back(participant_.subscribe_with_info<msg::LocalizerShardPubSubType>(
      dds::kLocalizerShardTopic,
      [this, changed](const msg::LocalizerShard& m, const eprosima::fastdds::dds::SampleInfo& info) {
        const std::string writer = dds::writer_id(info.publication_handle);
        changed([&] {
          // Bad announcements are refused and counted; membership keys on the writer alone.
          if (m.shard() != writer) return refuse_announcement("localizer_shard.id_not_its_writer");
          if (m.estimator().size() > kMaxShardTextLength || m.participant().size() > kMaxShardTextLength) {
            return refuse_announcement("localizer_shard.text_too_long");
          }
          switch (shard_->on_announcement(writer, m.estimator())) {
            case ShardMembership::Announcement::kLiveSetChanged:
              return true;
            case ShardMembership::Announcement::kEstimatorChanged:
              return refuse_announcement("localizer_shard.estimator_changed");
            case ShardMembership::Announcement::kNoChange:
              break;
          }
          return false;
        });
      },
      events));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shard_->start_settling(dds::steady_clock_ns());  // now that it hears the others
  }
  const eprosima::fastdds::dds::LivelinessQosPolicy heard = readers_.back()->get_qos().liveliness();
  if (heard.kind != eprosima::fastdds::dds::MANUAL_BY_TOPIC_LIVELINESS_QOS ||
      !(shard_writer_->get_qos().liveliness().lease_duration <= heard.lease_duration)) {
    // Incompatible with its own writer: the shards would never match, each serving every robot.
    throw dds::DdsError(
        "profile localizer_shard.reader: manual-by-topic liveliness with a lease at least the writer's");
  }
  shard_liveliness_ = std::make_unique<dds::PeriodicTask>(
      std::max(std::chrono::milliseconds(1),
               std::chrono::milliseconds(shard_lease_ns_ / kShardAssertionsPerLease / kNsPerMillisecond)),
      [this] { keep_shard_alive(); });
}

bool LocalizerParticipant::refuse_announcement(const std::string& reason) {
  ++shard_announcements_refused_[reason];
  return false;
}

void LocalizerParticipant::keep_shard_alive() {
  bool announce = false, assert_now = false;
  {
    // Only a localizer that can take its lock asserts: one stuck under it (a hung estimator) is
    // taken for gone, and its robots served by the others.
    std::lock_guard<std::mutex> lock(mutex_);
    const StampNs now_ns = dds::steady_clock_ns();
    check_shard_stall(now_ns);
    // Alive to the others only once settled: they hand its share over as it starts serving it.
    if (shard_->settled(now_ns)) {
      assert_now = true;
      // Announced once settled, and again whenever a reader matched since: a shard that lost and
      // found it again (a partition, a stall past the participant's lease) may not be sent a
      // sample it was sent before.
      const bool new_reader = shard_matches_.matched_since_asked();
      if (!shard_announced_ || new_reader) announce = shard_announced_ = true;
      shard_asserted_ns_ = now_ns;
    }
  }
  // Outside the lock: Fast DDS may tell this participant's own reader at once, whose callback
  // takes it.
  if (announce) {
    msg::LocalizerShard m;
    m.shard(shard_->self());
    m.participant(participant_.name());
    m.estimator(core_.estimator_name());
    shard_writer_->write(&m);
  }
  if (assert_now) shard_writer_->assert_liveliness();
}

bool LocalizerParticipant::check_shard_stall(StampNs now_ns) {
  // Past the lease less one assertion period: the others' lease runs from when an assertion
  // reached them, a little after it was sent.
  const StampNs stalled_after_ns = shard_lease_ns_ - shard_lease_ns_ / kShardAssertionsPerLease;
  if (!shard_ || !shard_asserted_ns_ || now_ns - *shard_asserted_ns_ <= stalled_after_ns) return false;
  // Stalled past its lease (stopped, starved, stuck): the others took its robots over and served
  // them since, while its estimators missed that time. Every robot goes; it settles again,
  // silent meanwhile, so that the others serve on until it is alive again and then hand its share
  // back at once, to fresh estimators. Told here by the first sample after the stall as well as
  // by the liveliness task, whichever runs first.
  for (const std::string& robot_id : core_.robot_ids()) release_robot(robot_id);
  conflicts_.set_own_robots({}, now_ns);
  robots_told_ = 0;
  ++shard_stalls_;
  shard_asserted_ns_.reset();
  shard_->start_settling(now_ns);
  return true;
}

void LocalizerParticipant::release_robot(const std::string& robot_id) {
  core_.release_robot(robot_id);
  odometry_sequence_.erase(robot_id);
  plan_sent_ns_.erase(robot_id);
  ++robots_handed_over_;
}

void LocalizerParticipant::release_robots_not_served() {
  const StampNs now_ns = dds::steady_clock_ns();
  for (const std::string& robot_id : core_.robot_ids()) {
    if (!shard_->serves(robot_id, now_ns)) release_robot(robot_id);
  }
  conflicts_.set_own_robots(core_.robot_ids(), now_ns);
  robots_told_ = core_.robot_count();
}

void LocalizerParticipant::on_peer_diagnostics(const msg::Diagnostics& d, const std::string& writer) {
  if (writer == own_diagnostics_writer_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (d.robots_localized().size() > msg::DIAGNOSTICS_MAX_ROBOTS) {
    ++peer_reports_refused_;  // beyond the wire contract's bound: a broken or hostile peer
    return;
  }
  conflicts_.on_peer_report(writer, d.participant(),
                            {d.robots_localized().begin(), d.robots_localized().end()}, dds::steady_clock_ns());
}

void LocalizerParticipant::on_odometry(const msg::Odometry& m) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (serves(m.robot_id())) fuse_odometry(m);
    newest_odometry_stamp_ns_ = std::max(newest_odometry_stamp_ns_.load(), m.stamp_ns());
  }
  ++odometry_processed_;
}

void LocalizerParticipant::fuse_odometry(const msg::Odometry& m) {
  // Increments the bus dropped (a history too short for a stalled reader): counted, since an
  // estimator integrating odometry cannot see that a 10 ms step is missing.
  if (core_.serves(m.robot_id())) {
    auto [last, first] = odometry_sequence_.try_emplace(m.robot_id(), m.sequence_number());
    const std::uint64_t seq = m.sequence_number();
    const std::uint64_t distance = seq > last->second ? seq - last->second : last->second - seq;
    if (!first && distance > kSequenceRestart) {
      // Far back (a restarted gateway numbering from 0 again) or far ahead (another writer, a
      // corrupted number): a new numbering, not that many lost samples.
      last->second = seq;
      ++sequence_restarts_;
    } else if (!first && seq > last->second) {
      lost_increments_ += seq - last->second - 1;
      last->second = seq;
    }
  }
  if (auto out = core_.on_odometry(m.robot_id(), dds::from_msg(m))) {
    publish(*out);
    publish_firing_plan(m.robot_id(), out->estimate.stamp_ns);
  }
  share_calibration();
}

void LocalizerParticipant::publish_firing_plan(const std::string& robot_id, StampNs stamp_ns) {
  if (!plan_writer_) return;
  const auto sent = plan_sent_ns_.find(robot_id);
  if (sent != plan_sent_ns_.end() && stamp_ns >= sent->second && stamp_ns - sent->second < kFiringPlanPeriodNs) return;
  const std::optional<FiringPlan> plan = core_.firing_plan(robot_id);
  if (!plan) return;  // no trusted pose to plan from: the gateway's plan goes stale, and it fires every beacon
  msg::FiringPlan m;
  m.robot_id(robot_id);
  m.stamp_ns(plan->stamp_ns);
  m.beacon_ids(plan->beacon_ids);
  plan_writer_->write(&m);
  plan_sent_ns_[robot_id] = stamp_ns;
  ++plans_sent_;
}

void LocalizerParticipant::publish(const LocalizerOutput& out) {
  // A sample taken before a stall and fused after it: its robot was just released, no pose.
  if (check_shard_stall(dds::steady_clock_ns())) return;
  if (core_.robot_count() != robots_told_) {  // a new robot: is it contested? (once per robot)
    conflicts_.set_own_robots(core_.robot_ids(), dds::steady_clock_ns());
    robots_told_ = core_.robot_count();
  }
  PoseEstimate estimate = out.estimate;
  estimate.status = conflicts_.status_of(out.robot_id, estimate.status);
  // Against one of two disagreeing maps, a pose is no better than the map it was computed on.
  if (map_sources_.disagree() && estimate.status == PoseStatus::kOk) estimate.status = PoseStatus::kDegraded;
  auto p = dds::to_msg(out.robot_id, estimate, core_.estimator_name(), out.beacons_used);
  pose_writer_->write(&p);
  ++poses_written_;
  if (!out.state.empty()) {
    msg::EstimatorState state;
    state.robot_id(out.robot_id);
    state.stamp_ns(estimate.stamp_ns);
    state.estimator(core_.estimator_name());
    for (const Estimator::StateValue& v : out.state) {
      msg::EstimatorStateValue value;
      value.name(v.name);
      value.value(v.value);
      value.sigma(v.sigma);
      state.values().push_back(value);
    }
    state_writer_->write(&state);
  }
}

void LocalizerParticipant::share_calibration() {
  if (core_.calibration_revision() == calibration_shared_revision_) return;
  calibration_shared_revision_ = core_.calibration_revision();
  auto m = dds::to_msg(core_.calibration(), map_frame_id_);
  calibration_writer_->write(&m);
  if (options_.calibration_file.empty()) return;
  // A few times per drive (each group calibrated once, again after the backwards drive): the
  // write and its two flushes to the disk (milliseconds) hold this robot's samples that long.
  const CalibrationFileResult saved = save_calibration(options_.calibration_file, core_.calibration());
  if (saved.ok()) {
    calibration_save_error_.clear();
  } else {
    ++calibration_saves_failed_;
    calibration_save_error_ = std::string(to_string(saved.problem)) + ": " + saved.detail;
  }
}

msg::Diagnostics LocalizerParticipant::diagnostics_snapshot() {
  std::lock_guard<std::mutex> lock(mutex_);
  check_shard_stall(dds::steady_clock_ns());  // never the robots held through a stall
  std::vector<std::string> robots = core_.robot_ids();
  conflicts_.set_own_robots(robots, dds::steady_clock_ns());  // and drops the peers gone silent
  const PoseStatus worst = core_.worst_status();
  msg::ParticipantStatus status = msg::PARTICIPANT_STATUS_OK;
  std::string message =
      std::to_string(core_.robot_count()) + " robot(s), worst pose status " + to_string(worst);
  if (!core_.has_beacon_map()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "waiting for the beacon map";
  } else if (odometry_writer_lost_.load()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "no live odometry writer: the gateway was lost";
  } else if (range_writer_lost_.load()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "no live range writer: the decoder was lost";
  } else if (const auto silent = core_.odometry_silent_robots(); !silent.empty()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "no odometry within its deadline for " + std::to_string(silent.size()) + " robot(s), first " +
              silent.front() + ": the gateway stopped or hung";
  } else if (core_.robot_count() == 0) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "no robot heard yet (no odometry)";
  } else if (worst != PoseStatus::kOk) {
    // A robot without a trusted pose (initializing, degraded, lost): not ok, whatever the
    // others have; the message says what the initializing ones wait for.
    status = msg::PARTICIPANT_STATUS_DEGRADED;
  }
  // The robots without a pose yet, and what they wait for.
  if (const StartupSummary startup = core_.startup_summary(); !startup.empty())
    message += "; " + startup.describe();
  message += "; " + std::to_string(core_.replays()) + " late measurement(s) fused at their stamp";
  if (core_.beacon_map_changes()) {
    message += "; beacon map replaced " + std::to_string(core_.beacon_map_changes()) +
               " time(s), every robot restarted on it";
  }
  if (shard_) {
    const StampNs now_ns = dds::steady_clock_ns();
    message += "; shard: " + std::to_string(shard_->live_shards()) + " live shard(s) of " + core_.estimator_name() +
               (shard_->settled(now_ns) ? "" : ", settling (serving none yet)") + ", " +
               std::to_string(robots_handed_over_) + " robot(s) released, " +
               std::to_string(other_shard_samples_) +
               " sample(s) of robots it does not serve (other shards', or while settling)";
    if (shard_stalls_) {
      message += ", " + std::to_string(shard_stalls_) + " stall(s) past its lease (every robot released)";
    }
    if (shard_->other_estimator_shards()) {
      // Another estimator's fleet serves the same robots: the serving conflicts say so.
      message += ", " + std::to_string(shard_->other_estimator_shards()) + " shard(s) of other estimators";
    }
  }
  if (plan_writer_) message += "; selective activation: " + std::to_string(plans_sent_) + " firing plan(s) sent";
  if (!core_.calibration().groups.empty()) {
    message += "; beacon calibration: " + std::to_string(core_.calibration().groups.size()) + " group(s)";
  }
  if (!calibration_save_error_.empty()) {
    // The newest calibration would not survive a restart.
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "beacon calibration not saved to " + options_.calibration_file + " (" + calibration_save_error_ +
              "); " + message;
  }
  if (map_sources_.disagree()) {
    // Whichever map arrived last is in use; the robots flip between layouts as the maps arrive.
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "beacon maps disagree: " + map_sources_.describe() + ", the newest is in use; " + message;
  }
  if (conflicts_.contested_robots()) {
    // Its poses of those robots go out degraded; the other localizer reports the same.
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "serving conflict: " + conflicts_.describe() + "; its poses are degraded; " + message;
  }
  if (robots.size() > msg::DIAGNOSTICS_MAX_ROBOTS) {
    message += "; robots listed: the first " + std::to_string(msg::DIAGNOSTICS_MAX_ROBOTS) + " of " +
               std::to_string(robots.size());
    robots.resize(msg::DIAGNOSTICS_MAX_ROBOTS);
  }
  RejectionCounter counts = core_.counts();
  counts.reject("odometry.lost_increment", lost_increments_);
  counts.reject("odometry.sequence_restart", sequence_restarts_);
  counts.reject("diagnostics.too_many_robots", peer_reports_refused_);
  counts.reject("calibration_file.write_failed", calibration_saves_failed_);
  counts.reject("calibration.too_many_beacons", calibrations_refused_too_large_);
  counts.reject("calibration.other_frame", calibrations_refused_other_frame_);
  counts.reject(dds::kMapReaderRecreated, map_reader_->recreated());
  for (const auto& [reason, n] : shard_announcements_refused_) counts.reject(reason, n);
  auto d = dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), counts, deadline_misses_.load(),
                                 status, message);
  d.writers_lost(odometry_writers_lost_.load() + range_writers_lost_.load());
  d.robots_localized(std::move(robots));
  d.serving_conflicts(conflicts_.conflicts_found());
  return d;
}

}  // namespace beaconloc
