// The latency benchmark's shared helpers: the steady clock in ns, the stop check, match counts.
#include "common.hpp"

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

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
