#include "pose_sink.hpp"

#include <beaconlocPubSubTypes.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "bench_support.hpp"

namespace beaconloc::bench {

namespace {
std::atomic<bool> g_stop{false};

}  // namespace

int run_sink(const dds::DdsOptions& dds, StampNs from_ns, StampNs to_ns) {
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
  std::mutex mutex;
  std::map<std::string, StampNs> last_stamp;
  std::uint64_t poses = 0, corrections = 0;
  std::vector<double> ages_ms;
  ages_ms.reserve(1 << 20);
  dds::Participant participant(dds, "beaconloc.bench.pose_sink");
  dds::Reader reader = participant.subscribe<msg::PoseEstimatePubSubType>(
      dds::kPoseEstimateTopic, [&](const msg::PoseEstimate& m) {
        const StampNs now = dds::wall_clock_ns();
        if (m.stamp_ns() < from_ns || m.stamp_ns() > to_ns) return;
        std::lock_guard<std::mutex> lock(mutex);
        auto [it, first] = last_stamp.try_emplace(m.robot_id(), m.stamp_ns());
        if (!first && it->second == m.stamp_ns()) {
          ++corrections;
        } else {
          it->second = m.stamp_ns();
          ++poses;
        }
        if (ages_ms.size() < ages_ms.capacity()) ages_ms.push_back(ns_to_s(now - m.stamp_ns()) * 1e3);
      });
  while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  reader.reset();  // no callback runs after this: the counts are final
  std::lock_guard<std::mutex> lock(mutex);
  std::printf("sink poses=%llu corrections=%llu robots=%zu age_p50_ms=%.3f age_p99_ms=%.3f age_max_ms=%.3f\n",
              static_cast<unsigned long long>(poses), static_cast<unsigned long long>(corrections),
              last_stamp.size(), percentile(ages_ms, 0.5), percentile(ages_ms, 0.99),
              percentile(ages_ms, 1.0));
  return 0;
}

}  // namespace beaconloc::bench
