// The latency benchmark's shared helpers: the steady clock in ns, the stop check, match counts.
#include "common.hpp"

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include <unistd.h>

#include <fstream>
#include <sstream>

#include "beaconloc/dds/stop_signal.hpp"

namespace beaconloc::latency {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

void check_stop() {
  if (dds::stop_requested()) throw Stopped();
}

dds::DdsOptions bench_dds_options(int domain, const Transport& t) {
  dds::DdsOptions o;
  o.domain_id = domain;
  o.participant_profile = t.profile;
  if (!t.keystore.empty()) o.security = {t.keystore, kBenchEnclave};
  return o;
}

double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error("cannot read /proc/" + std::to_string(pid) + "/stat");
  // Fields after the command's closing parenthesis: state is field 3, utime 14, stime 15.
  std::istringstream rest(line.substr(line.rfind(')') + 2));
  std::string field;
  double utime = 0.0, stime = 0.0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

int matched_readers(eprosima::fastdds::dds::DataWriter* w) {
  eprosima::fastdds::dds::PublicationMatchedStatus s;
  w->get_publication_matched_status(s);
  return s.current_count;
}

int matched_writers(eprosima::fastdds::dds::DataReader* r) {
  eprosima::fastdds::dds::SubscriptionMatchedStatus s;
  r->get_subscription_matched_status(s);
  return s.current_count;
}

}  // namespace beaconloc::latency
