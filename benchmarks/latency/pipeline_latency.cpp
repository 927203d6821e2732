// The pipeline's latency (see main.cpp): this process plays the gateway (the built-in simulated
// scenario at its real rates, paced by the wall clock: 100 Hz odometry, one beacon slot every
// 200 ms heard by the robot's three receivers) and reads beaconloc/pose_estimate, while `beaconloc
// decoder` and `beaconloc localizer` run as child processes. The latency of a slot: steady_clock
// just before the write of the slot's first RawTof -> steady_clock at the arrival here of the
// first PoseEstimate after it whose beacons_used holds that beacon (within --match-window-ms).
// Only the first TOF of a slot is timed: the slot's other TOFs carry the same beacon id and follow
// within microseconds, so a pose could not be told apart from theirs (they are still written: the
// load is real).
#include "pipeline_latency.hpp"

#include <beaconlocPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iterator>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "bench_support.hpp"
#include "child.hpp"
#include "sim/scenario.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc::latency {

namespace {

using namespace std::chrono_literals;
using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::DataWriter;

struct TofWrite {
  std::int64_t write_ns;  // steady clock, just before write()
  std::uint32_t beacon_id;
  bool timed;  // first TOF of its slot, inside the measured window
};

struct PoseArrival {
  std::int64_t arrival_ns;  // steady clock, in the reader's callback
  std::int64_t stamp_ns;
  std::vector<std::uint32_t> beacons_used;
};

std::string number(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

std::string join_receivers(const ReceiverArray& r) {
  std::ostringstream s;
  s << std::setprecision(10);
  for (std::size_t i = 0; i < r.size(); ++i)
    s << (i ? "," : "") << r.receivers_base_m[i].x() << ':' << r.receivers_base_m[i].y();
  return s.str();
}

// Matching: each timed TOF to the first pose that arrived after its write, within window_ns, and
// lists its beacon. poses are in arrival order.
void match(const std::vector<TofWrite>& tofs, const std::vector<PoseArrival>& poses, std::int64_t window_ns,
           PipelineResult& result) {
  result.tofs_written = tofs.size();
  result.poses = poses.size();
  if (poses.size() > 1) {
    result.pose_rate_hz = static_cast<double>(poses.size() - 1) /
                          (static_cast<double>(poses.back().arrival_ns - poses.front().arrival_ns) * 1e-9);
  }
  for (const auto& tof : tofs) {
    if (!tof.timed) continue;
    ++result.timed;
    auto it = std::lower_bound(poses.begin(), poses.end(), tof.write_ns,
                               [](const PoseArrival& p, std::int64_t ns) { return p.arrival_ns < ns; });
    for (; it != poses.end() && it->arrival_ns <= tof.write_ns + window_ns; ++it) {
      if (std::find(it->beacons_used.begin(), it->beacons_used.end(), tof.beacon_id) ==
          it->beacons_used.end())
        continue;
      result.latency_us.push_back(static_cast<double>(it->arrival_ns - tof.write_ns) * 1e-3);
      if (it != poses.begin() && std::prev(it)->stamp_ns == it->stamp_ns) ++result.correction_matches;
      break;
    }
  }
}

}  // namespace

PipelineResult run_pipeline(const Settings& st, const Transport& t) {
  const sim::Scenario scenario = sim::default_scenario();
  sim::SimSource source(scenario, st.seed);
  const std::string domain = std::to_string(st.pipeline_domain);
  const Pose2 start = scenario.trajectory.pose_at(0.0);

  std::vector<std::string> localizer_argv{st.cli,
                                          "localizer",
                                          "--domain",
                                          domain,
                                          "--participant-profile",
                                          t.profile,
                                          "--estimator",
                                          st.estimator,
                                          "--receivers",
                                          join_receivers(scenario.receivers),
                                          "--receiver-height-m",
                                          number(scenario.receivers.receiver_height_m),
                                          "--initial-pose",
                                          number(start.x()),
                                          number(start.y()),
                                          number(start.z())};
  std::vector<std::string> decoder_argv{st.cli,
                                        "decoder",
                                        "--domain",
                                        domain,
                                        "--participant-profile",
                                        t.profile,
                                        "--min-range-m",
                                        number(scenario.min_range_m),
                                        "--max-range-m",
                                        number(scenario.max_range_m),
                                        "--range-sigma-m",
                                        number(scenario.range_sigma_m)};
  if (!t.keystore.empty()) {
    for (auto* argv : {&localizer_argv, &decoder_argv}) {
      argv->push_back("--keystore");
      argv->push_back(t.keystore);
    }
  }
  Child localizer("localizer", localizer_argv, st.log_dir + "/" + t.name + "-localizer.log");
  Child decoder("decoder", decoder_argv, st.log_dir + "/" + t.name + "-decoder.log");
  std::vector<Child*> children{&localizer, &decoder};

  std::mutex poses_mutex;
  std::vector<PoseArrival> poses;
  const auto total_s = st.warmup_s + st.duration_s + 0.5;  // 0.5 s tail: the last poses arrive
  poses.reserve(static_cast<std::size_t>(total_s * 150.0) + 1000);
  std::vector<TofWrite> tofs;
  tofs.reserve(static_cast<std::size_t>(total_s * 20.0) + 100);

  PipelineResult result;
  {
    dds::Participant participant(bench_dds_options(st.pipeline_domain, t), "beaconloc.latency.gateway");
    dds::Writer map_writer = participant.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
    dds::Writer tof_writer = participant.robot_writer<msg::RawTofPubSubType>(dds::kRawTofTopic, kRobotId);
    dds::Writer odometry_writer =
        participant.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, kRobotId);
    dds::Reader pose_reader = participant.subscribe<msg::PoseEstimatePubSubType>(
        dds::kPoseEstimateTopic, [&](const msg::PoseEstimate& m) {
          const std::int64_t arrival = now_ns();
          std::lock_guard<std::mutex> lock(poses_mutex);
          poses.push_back({arrival, m.stamp_ns(), {m.beacons_used().begin(), m.beacons_used().end()}});
        });
    // Ready: decoder and localizer read the map, the decoder the TOFs, the localizer the odometry,
    // and the localizer's pose writer matched this reader.
    wait_until(
        "the decoder and localizer to match",
        [&] {
          return matched_readers(map_writer.get()) >= 2 && matched_readers(tof_writer.get()) >= 1 &&
                 matched_readers(odometry_writer.get()) >= 1 && matched_writers(pose_reader.get()) >= 1;
        },
        30s, children);
    // The same liveliness assertion as the gateway (manual by topic, lease 1 s).
    auto liveliness = std::make_unique<dds::PeriodicTask>(250ms, [&] {
      tof_writer->assert_liveliness();
      odometry_writer->assert_liveliness();
    });
    auto map = dds::to_msg(source.beacon_map(), "map");
    map_writer->write(&map);

    // The gateway's loop (plugins/gateway/gateway_participant.cpp): 10 ms steps in real time,
    // simulated stamps offset to the wall clock.
    const StampNs offset_ns = dds::wall_clock_ns();
    const StampNs step_ns = 10 * kNsPerMillisecond;
    const StampNs warmup_ns = s_to_ns(st.warmup_s);
    const StampNs measured_end_ns = s_to_ns(st.warmup_s + st.duration_s);
    const StampNs end_ns = s_to_ns(total_s);
    std::uint64_t odometry_sequence = 0;
    StampNs last_fire_ns = -1;
    std::vector<SourceEvent> events;
    const auto wall_start = Clock::now();
    StampNs next_check_ns = kNsPerSecond;
    // The children's CPU over the measured window: read at its first and last step.
    const auto children_cpu_s = [&] {
      return bench::process_cpu_s(localizer.pid()) + bench::process_cpu_s(decoder.pid());
    };
    double window_cpu_start_s = 0.0;
    Clock::time_point window_wall_start;
    bool in_window = false;
    for (StampNs t_ns = 0; t_ns <= end_ns; t_ns += step_ns) {
      events.clear();
      source.advance(t_ns, events);
      std::this_thread::sleep_until(wall_start + std::chrono::nanoseconds(t_ns));
      if (!in_window && t_ns >= warmup_ns && t_ns < measured_end_ns) {
        in_window = true;
        window_cpu_start_s = children_cpu_s();
        window_wall_start = Clock::now();
      } else if (in_window && t_ns >= measured_end_ns) {
        in_window = false;
        result.children_cpu_s = children_cpu_s() - window_cpu_start_s;
        result.window_s = std::chrono::duration<double>(Clock::now() - window_wall_start).count();
      }
      for (auto& e : events) {
        if (e.kind == SourceEvent::Kind::kTof) {
          const StampNs fire_ns = e.tof.fire_stamp_ns;
          const bool first_of_slot = fire_ns != last_fire_ns;
          last_fire_ns = fire_ns;
          e.tof.fire_stamp_ns += offset_ns;
          auto m = dds::to_msg(kRobotId, e.tof);
          const std::int64_t before = now_ns();
          if (!tof_writer->write(&m)) throw std::runtime_error("RawTof write failed");
          if (in_window) ++result.window_samples;
          tofs.push_back(
              {before, e.tof.beacon_id, first_of_slot && fire_ns >= warmup_ns && fire_ns < measured_end_ns});
        } else if (e.kind == SourceEvent::Kind::kOdometry) {
          e.odometry.stamp_ns = e.stamp_ns + offset_ns;
          auto m = dds::to_msg(kRobotId, e.odometry, odometry_sequence++);
          if (!odometry_writer->write(&m)) throw std::runtime_error("Odometry write failed");
          if (in_window) ++result.window_samples;
        }
      }
      if (t_ns >= next_check_ns) {  // once a second
        next_check_ns += kNsPerSecond;
        check_stop();
        require_alive(children);
      }
    }
    liveliness.reset();
  }
  // Stop the children now (they leave cleanly on SIGTERM) and say if one failed.
  for (auto* c : children) {
    const auto s = c->stop();
    if (s && *s != 0) {
      std::fprintf(stderr, "latency: %s exited with status %d (log %s)\n", c->name().c_str(), *s,
                   c->log_path().c_str());
    }
  }
  match(tofs, poses, static_cast<std::int64_t>(st.match_window_ms * 1e6), result);
  return result;
}

}  // namespace beaconloc::latency
