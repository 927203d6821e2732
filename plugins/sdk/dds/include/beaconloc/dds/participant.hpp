#pragma once
// A DomainParticipant with its publisher and subscriber, created from the XML profiles. Owns and
// deletes every entity it creates. Thin: no logic beyond creating entities with named QoS.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/dds/topics.hpp"

namespace beaconloc::dds {

struct DdsOptions {
  int domain_id = 0;
  // The loopback-only profile keeps every packet on the machine (examples/qos/loopback.xml).
  std::string participant_profile = "beaconloc.loopback";
  std::vector<std::string> extra_qos_files;  // loaded after the embedded profiles
};

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads the embedded profiles, then each extra file. Throws DdsError naming a file that fails.
void load_qos_profiles(const std::vector<std::string>& extra_files);

// Takes every valid sample a reader has and hands it to a callback; counts missed deadlines.
template <class Msg>
class SampleListener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  SampleListener(std::function<void(const Msg&)> on_sample, std::atomic<std::uint64_t>* deadline_misses)
      : on_sample_(std::move(on_sample)), deadline_misses_(deadline_misses) {}
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    Msg m;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) on_sample_(m);
    }
  }
  void on_requested_deadline_missed(eprosima::fastdds::dds::DataReader*,
                                    const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& s) override {
    if (deadline_misses_) *deadline_misses_ += static_cast<std::uint64_t>(s.total_count_change);
  }

 private:
  std::function<void(const Msg&)> on_sample_;
  std::atomic<std::uint64_t>* deadline_misses_;
};

// Waits until every writer has at least one matched reader; false on timeout.
bool wait_for_matched_readers(const std::vector<eprosima::fastdds::dds::DataWriter*>& writers,
                              std::chrono::milliseconds timeout);

class Participant {
 public:
  Participant(const DdsOptions& options, const std::string& name);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  template <class PubSubType>
  eprosima::fastdds::dds::DataWriter* writer(const TopicSpec& spec,
                                             eprosima::fastdds::dds::DataWriterListener* listener = nullptr) {
    return make_writer(topic(spec.name, new PubSubType()), spec.writer_profile, listener);
  }
  // Subscribes with the topic's reader profile; on_sample runs on the reader's thread for each
  // valid sample. The participant owns the listener; close() before what on_sample uses dies.
  template <class PubSubType>
  eprosima::fastdds::dds::DataReader* subscribe(
      const TopicSpec& spec, std::function<void(const typename PubSubType::type&)> on_sample,
      std::atomic<std::uint64_t>* deadline_misses = nullptr) {
    listeners_.push_back(
        std::make_unique<SampleListener<typename PubSubType::type>>(std::move(on_sample), deadline_misses));
    return make_reader(topic(spec.name, new PubSubType()), spec.reader_profile, listeners_.back().get());
  }
  const std::string& name() const { return name_; }
  // Deletes readers and writers first: call before the listeners they use are destroyed.
  void close();

 private:
  eprosima::fastdds::dds::Topic* topic(const std::string& name, eprosima::fastdds::dds::TopicDataType* type);
  eprosima::fastdds::dds::DataWriter* make_writer(eprosima::fastdds::dds::Topic* topic,
                                                  const std::string& profile,
                                                  eprosima::fastdds::dds::DataWriterListener* l);
  eprosima::fastdds::dds::DataReader* make_reader(eprosima::fastdds::dds::Topic* topic,
                                                  const std::string& profile,
                                                  eprosima::fastdds::dds::DataReaderListener* l);

  std::string name_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> listeners_;
};

}  // namespace beaconloc::dds
