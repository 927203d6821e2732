#include "beaconloc/dds/participant.hpp"

#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <string_view>
#include <thread>
#include <utility>

#include "qos_profile_names.hpp"

namespace beaconloc::embedded {
extern const std::string_view kLoopbackProfilesXml;
extern const std::string_view kTopicProfilesXml;
extern const std::string_view kRos2TopicProfilesXml;
}  // namespace beaconloc::embedded

namespace beaconloc::dds {

using namespace eprosima::fastdds::dds;

void load_qos_profiles(const std::vector<std::string>& extra_files) {
  static std::mutex mutex;
  static bool embedded_loaded = false;
  static QosProfileNames names;               // every profile loaded so far
  static std::set<std::string> files_loaded;  // each file once per process (one per participant asks)
  std::lock_guard<std::mutex> lock(mutex);
  auto* factory = DomainParticipantFactory::get_instance();
  if (!embedded_loaded) {
    for (std::string_view xml :
         {embedded::kLoopbackProfilesXml, embedded::kTopicProfilesXml, embedded::kRos2TopicProfilesXml}) {
      names.add(std::string(xml), "the built-in QoS profiles");
      if (factory->load_XML_profiles_string(xml.data(), xml.size()) != ReturnCode_t::RETCODE_OK) {
        throw DdsError("the embedded QoS profiles failed to load");
      }
    }
    embedded_loaded = true;
  }
  for (const auto& file : extra_files) {
    std::ifstream in(file);
    if (!in.good()) throw DdsError("QoS file '" + file + "' cannot be read");
    std::error_code ignored;
    const std::string canonical = std::filesystem::weakly_canonical(file, ignored).string();
    if (files_loaded.count(canonical)) continue;
    std::stringstream text;
    text << in.rdbuf();
    names.add(text.str(), "QoS file '" + file + "'");
    if (factory->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK) {
      throw DdsError("QoS file '" + file + "' is not a valid Fast DDS profiles file");
    }
    files_loaded.insert(canonical);
  }
}

bool wait_for_matched_readers(const std::vector<DataWriter*>& writers, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    bool all = true;
    for (auto* w : writers) {
      PublicationMatchedStatus status;
      w->get_publication_matched_status(status);
      all = all && status.current_count > 0;
    }
    if (all) return true;
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

Participant::Participant(const DdsOptions& options, const std::string& name) : name_(name) {
  if (options.domain_id < 0 || options.domain_id > 232) {
    throw DdsError("domain id " + std::to_string(options.domain_id) + " is outside 0..232");
  }
  load_qos_profiles(options.extra_qos_files);
  auto* factory = DomainParticipantFactory::get_instance();
  DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.participant_profile, qos) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsError("participant profile '" + options.participant_profile + "' is not defined");
  }
  qos.name(name);
  participant_ = factory->create_participant(options.domain_id, qos);
  if (!participant_) throw DdsError("cannot create participant '" + name + "'");
  publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (!publisher_ || !subscriber_) throw DdsError("cannot create publisher/subscriber");
}

Participant::~Participant() {
  if (const int live = live_handles_.load(); live > 0) {
    // A handle declared before its participant: deleting the participant now would leave it
    // pointing into freed entities. A programming error, made loud.
    std::fprintf(stderr, "beaconloc: participant '%s' destroyed before %d of its readers or writers\n",
                 name_.c_str(), live);
    std::abort();
  }
  if (participant_) {
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}

void delete_entity(Publisher* parent, DataWriter* entity) { parent->delete_datawriter(entity); }
void delete_entity(Subscriber* parent, DataReader* entity) { parent->delete_datareader(entity); }

Topic* Participant::topic(const std::string& name, TopicDataType* type) {
  TypeSupport support(type);
  auto it = topics_.find(name);
  if (it != topics_.end()) return it->second;
  if (support.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
    throw DdsError("cannot register type " + support.get_type_name());
  }
  Topic* t = participant_->create_topic(name, support.get_type_name(), TOPIC_QOS_DEFAULT);
  if (!t) throw DdsError("cannot create topic " + name);
  topics_[name] = t;
  return t;
}

Writer Participant::make_writer(Topic* topic, const std::string& profile, DataWriterListener* listener) {
  DataWriter* w = publisher_->create_datawriter_with_profile(topic, profile, listener);
  if (!w) throw DdsError("cannot create writer on " + topic->get_name() + " with profile " + profile);
  return Writer(publisher_, w, nullptr, &live_handles_);
}

Reader Participant::make_reader(Topic* topic, const std::string& profile, std::unique_ptr<DataReaderListener> owned,
                                DataReaderListener* borrowed) {
  DataReaderListener* listener = owned ? owned.get() : borrowed;
  DataReader* r = subscriber_->create_datareader_with_profile(topic, profile, listener);
  if (!r) throw DdsError("cannot create reader on " + topic->get_name() + " with profile " + profile);
  return Reader(subscriber_, r, std::move(owned), &live_handles_);
}

}  // namespace beaconloc::dds
