#pragma once
// What the latency benchmark's parts share: its settings, the transports, the steady clock in
// nanoseconds, the stop on a signal (Stopped) and the DDS match counts.
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace eprosima::fastdds::dds {
class DataReader;
class DataWriter;
}  // namespace eprosima::fastdds::dds

namespace beaconloc::latency {

using Clock = std::chrono::steady_clock;

// Hops of the pipeline: gateway -> decoder (raw_tof), decoder -> localizer (beacon_range),
// localizer -> the benchmark (pose_estimate).
constexpr int kPipelineHops = 3;
constexpr const char* kRobotId = "robot1";

struct Transport {
  std::string name;     // shm, udp, shm+security, udp+security
  std::string profile;  // participant profile (examples/qos/loopback.xml)
  // DDS Security on with this keystore (scripts/deployment-keys.sh): this process and the echo as
  // enclave kBenchEnclave, the decoder and localizer as their roles'. Empty: off.
  std::string keystore;
};

// The benchmark's identity in a secured run (the script's role "bench").
constexpr const char* kBenchEnclave = "/beaconloc/bench";
// The options of this process's participants (and the echo's) for transport t.
dds::DdsOptions bench_dds_options(int domain, const Transport& t);


struct Settings {
  std::string cli;   // the beaconloc executable (decoder and localizer)
  std::string self;  // this executable (the echo peer)
  std::string estimator = "range_ekf";
  std::uint64_t seed = 1;
  int pipeline_domain = -1;
  int hop_domain = -1;
  double warmup_s = 3.0;
  double duration_s = 20.0;
  double hop_duration_s = 20.0;
  double hop_period_ms = 10.0;
  double b2b_hop_s = 5.0;
  double match_window_ms = 150.0;
  std::string log_dir;
};

// steady_clock now, in ns since its epoch.
std::int64_t now_ns();

// Thrown by check_stop() once SIGINT, SIGTERM, SIGHUP or SIGPIPE arrived (dds::install_stop_handlers).
class Stopped : public std::runtime_error {
 public:
  Stopped() : std::runtime_error("stopped by a signal") {}
};
void check_stop();

int matched_readers(eprosima::fastdds::dds::DataWriter* w);
int matched_writers(eprosima::fastdds::dds::DataReader* r);

}  // namespace beaconloc::latency
