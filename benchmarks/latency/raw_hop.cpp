// The raw Fast DDS hop: the echo peer, and the ping-pong against it (paced, then back-to-back).
// The ping is a RawTof (the same type, robot id and so serialized size as the pipeline's TOFs);
// each round trip is timed by this process's steady_clock from just before write() to the pong's
// arrival in the reader's listener.
#include "raw_hop.hpp"

#include <beaconlocPubSubTypes.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "bench_support.hpp"
#include "child.hpp"

namespace beaconloc::latency {

namespace {

using namespace std::chrono_literals;
using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::DataWriter;

constexpr dds::TopicSpec kPingTopic{"beaconloc_latency/ping", "raw_tof.writer", "raw_tof.reader"};
constexpr dds::TopicSpec kPongTopic{"beaconloc_latency/pong", "raw_tof.writer", "raw_tof.reader"};

msg::RawTof ping_sample(std::uint64_t sequence) {
  RawTofSample s;
  s.beacon_id = 1;
  s.receiver_id = 0;
  s.fire_stamp_ns = dds::wall_clock_ns();
  s.tof_s = 0.006;
  s.beacon_temperature_c = 22.0;
  s.sequence_number = sequence;
  return dds::to_msg(kRobotId, s);
}

}  // namespace

int run_echo(int domain, const std::string& profile, const std::string& keystore) {
  dds::Participant participant(bench_dds_options(domain, {"echo", profile, keystore}), "beaconloc.latency.echo");
  dds::Writer pong = participant.writer<msg::RawTofPubSubType>(kPongTopic);
  dds::Reader reader = participant.subscribe<msg::RawTofPubSubType>(kPingTopic, [&pong](const msg::RawTof& m) {
    msg::RawTof copy = m;
    pong->write(&copy);
  });
  while (!dds::wait_for_stop(1s)) {
  }
  return 0;
}

HopResult run_hop(const Settings& st, const Transport& t) {
  const int domain = st.hop_domain;
  std::vector<std::string> echo_argv{st.self,    "--role",   "echo", "--domain", std::to_string(domain),
                                     "--profile", t.profile};
  if (!t.keystore.empty()) {
    echo_argv.push_back("--keystore");
    echo_argv.push_back(t.keystore);
  }
  Child echo("echo", echo_argv, st.log_dir + "/" + t.name + "-echo.log");
  std::vector<Child*> children{&echo};
  HopResult result;
  {
    dds::Participant participant(bench_dds_options(domain, t), "beaconloc.latency.ping");
    std::mutex mutex;
    std::condition_variable cv;
    std::uint64_t awaited = 0;
    std::int64_t sent_ns = 0;
    std::optional<std::int64_t> rtt_ns;
    dds::Writer ping = participant.writer<msg::RawTofPubSubType>(kPingTopic);
    dds::Reader pong_reader =
        participant.subscribe<msg::RawTofPubSubType>(kPongTopic, [&](const msg::RawTof& m) {
          const std::int64_t arrival = now_ns();
          std::lock_guard<std::mutex> lock(mutex);
          if (m.sequence_number() != awaited || rtt_ns) return;
          rtt_ns = arrival - sent_ns;
          cv.notify_all();
        });
    wait_until(
        "the echo peer to match",
        [&] { return matched_readers(ping.get()) >= 1 && matched_writers(pong_reader.get()) >= 1; }, 30s, children);
    auto liveliness = std::make_unique<dds::PeriodicTask>(250ms, [&] { ping->assert_liveliness(); });
    std::uint64_t sequence = 0;
    // One round trip: the time from just before write() to the pong's arrival in the listener
    // (nullopt: no pong within 1 s).
    auto round_trip = [&]() -> std::optional<std::int64_t> {
      auto m = ping_sample(++sequence);
      {
        std::lock_guard<std::mutex> lock(mutex);
        awaited = sequence;
        rtt_ns.reset();
        sent_ns = now_ns();
      }
      if (!ping->write(&m)) throw std::runtime_error("ping write failed");
      std::unique_lock<std::mutex> lock(mutex);
      if (!cv.wait_for(lock, 1s, [&] { return rtt_ns.has_value(); })) return std::nullopt;
      return rtt_ns;
    };
    // Probes until the echo answers (its reader may match after ours did).
    const auto probe_start = Clock::now();
    while (!round_trip()) {
      check_stop();
      require_alive(children);
      if (Clock::now() - probe_start > 30s) throw std::runtime_error("the echo peer never answered");
    }
    // Paced: one round trip per period, the first second not measured.
    const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(st.hop_period_ms * 1e6));
    const auto warmup = std::chrono::seconds(1);
    const auto measured =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(st.hop_duration_s));
    const auto begin = Clock::now();
    std::optional<double> echo_cpu_start_s;
    for (auto next = begin; next - begin < warmup + measured; next += period) {
      std::this_thread::sleep_until(next);
      const bool timed = Clock::now() - begin >= warmup;
      if (timed && !echo_cpu_start_s) echo_cpu_start_s = bench::process_cpu_s(echo.pid());
      const auto rtt = round_trip();
      if (timed) {
        ++result.sent;
        if (rtt) {
          result.hop_us.push_back(static_cast<double>(*rtt) * 1e-3 / 2.0);
        } else {
          ++result.lost;
        }
      }
      if ((sequence & 63) == 0) {
        check_stop();
        require_alive(children);
      }
    }
    if (echo_cpu_start_s) result.echo_cpu_s = bench::process_cpu_s(echo.pid()) - *echo_cpu_start_s;
    // Back-to-back, for reference (Fast DDS's figure on a hot path, TOOLCHAIN.md's ping-pong).
    const auto b2b = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(st.b2b_hop_s));
    const auto b2b_begin = Clock::now();
    while (Clock::now() - b2b_begin < b2b) {
      if (const auto rtt = round_trip()) result.b2b_hop_us.push_back(static_cast<double>(*rtt) * 1e-3 / 2.0);
      if ((sequence & 1023) == 0) {
        check_stop();
        require_alive(children);
      }
    }
    liveliness.reset();
  }
  const auto s = echo.stop();
  if (s && *s != 0) std::fprintf(stderr, "latency: the echo peer exited with status %d\n", *s);
  return result;
}

}  // namespace beaconloc::latency
