#include "beaconloc/dds/participant.hpp"

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <ctime>
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

void WriterRobots::on_publisher_discovery(DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERY_STATUS;
  const InstanceHandle_t writer(info.info.guid());
  std::lock_guard<std::mutex> lock(mutex_);
  if (info.status == Status::REMOVED_WRITER) {
    // Kept a while: samples it wrote may still wait in a reader's queue.
    retired_.push_back(writer);
    if (retired_.size() > kRetiredWriters) {
      robots_.erase(retired_.front());
      retired_.pop_front();
    }
    return;
  }
  const std::string prefix = robot_partition("");
  Entry seen;
  for (const std::string& partition : info.info.m_qos.m_partition.getNames()) {
    if (partition.rfind(prefix, 0) != 0) continue;
    seen.partitioned = true;
    seen.robots.push_back(partition.substr(prefix.size()));
  }
  const auto it = robots_.find(writer);
  if (info.status == Status::CHANGED_QOS_WRITER && it == robots_.end()) {
    robots_.emplace(writer, Entry{true, {}});  // a change of a writer forgotten: believed for no robot
    return;
  }
  if (info.status == Status::CHANGED_QOS_WRITER) {
    // Only ever narrowed: Fast DDS 2.9 tells a writer's new partitions before access control
    // judges them, and keeps the match when it refuses them, so a writer that moved to another
    // robot's partition must not be believed.
    std::vector<std::string> kept;
    for (const std::string& robot : it->second.robots) {
      if (std::find(seen.robots.begin(), seen.robots.end(), robot) != seen.robots.end()) kept.push_back(robot);
    }
    it->second.robots = std::move(kept);
    return;
  }
  if (it == robots_.end()) robots_.emplace(writer, std::move(seen));
}

void WriterRobots::add(const InstanceHandle_t& writer, std::vector<std::string> robots) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry e;
  e.partitioned = !robots.empty();
  e.robots = std::move(robots);
  robots_[writer] = std::move(e);
}

bool WriterRobots::may_speak_for(const InstanceHandle_t& writer, const std::string& robot_id, bool strict) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = robots_.find(writer);
  if (it == robots_.end() || !it->second.partitioned) return !strict;
  return std::find(it->second.robots.begin(), it->second.robots.end(), robot_id) != it->second.robots.end();
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
  if (options.transport) {
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports = {options.transport};
  }
  std::string enclave;
  if (options.security.enabled()) {
    if (options.domain_id > kMaxSecuredDomainId) {
      throw SecurityError("domain " + std::to_string(options.domain_id) + ": a secured deployment's governance "
                          "covers domains 0.." + std::to_string(kMaxSecuredDomainId) + " (scripts/deployment-keys.sh)");
    }
    enclave = options.security.enclave.empty() ? default_enclave(name) : options.security.enclave;
    enable_security(check_enclave(options.security, enclave, static_cast<std::int64_t>(std::time(nullptr))), qos);
    secured_ = true;
  }
  // What rmw puts in a ROS 2 participant's user data and ROS 2 tools read (ros2 node list, the
  // bridge's ros_discovery_info): the participant's security enclave, "/" when unsecured. It
  // replaces any <userData> of the participant profile (ours set none).
  const std::string user_data = "enclave=" + (enclave.empty() ? std::string("/") : enclave) + ";";
  qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(user_data.begin(), user_data.end()));
  // Only the discovery of publishers is listened to (WriterRobots): the entities' statuses go to
  // their own listeners.
  participant_ = factory->create_participant(options.domain_id, qos, &writer_robots_, StatusMask::none());
  if (!participant_) {
    if (secured_) {
      throw SecurityError("cannot create participant '" + name + "' as enclave " + enclave + " of keystore '" +
                          options.security.keystore +
                          "': Fast DDS refused its security (its log above may say why; the files passed "
                          "beaconloc's own checks)");
    }
    throw DdsError("cannot create participant '" + name + "'");
  }
  publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  SubscriberQos robot_qos = SUBSCRIBER_QOS_DEFAULT;
  robot_qos.partition().push_back((robot_partition("") + "*").c_str());
  if (!secured_) robot_qos.partition().push_back("");  // a tool's writer of many robots
  robot_subscriber_ = participant_->create_subscriber(robot_qos);
  if (!publisher_ || !subscriber_ || !robot_subscriber_) {
    // No destructor runs for a constructor that throws: the participant goes here, before the
    // listener it holds (writer_robots_) does.
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw DdsError("cannot create publisher/subscriber");
  }
}

Publisher* Participant::robot_publisher(const std::string& robot_id) {
  auto it = robot_publishers_.find(robot_id);
  if (it != robot_publishers_.end()) return it->second;
  PublisherQos qos = PUBLISHER_QOS_DEFAULT;
  qos.partition().push_back(robot_partition(robot_id).c_str());
  Publisher* p = participant_->create_publisher(qos);
  if (!p) throw DdsError("cannot create the publisher of robot '" + robot_id + "'");
  robot_publishers_[robot_id] = p;
  return p;
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

Writer Participant::make_writer(const TopicSpec& spec, Topic* topic, DataWriterListener* listener,
                                const std::string* robot_id) {
  Publisher* publisher = robot_id ? robot_publisher(*robot_id) : publisher_;
  DataWriter* w = publisher->create_datawriter_with_profile(topic, spec.writer_profile, listener);
  if (!w) {
    throw DdsError("cannot create writer on " + topic->get_name() + " with profile " + spec.writer_profile +
                   (robot_id ? " in partition " + robot_partition(*robot_id) : std::string()) +
                   (secured_ ? " (is it granted by this enclave's permissions?)" : ""));
  }
  // This participant's own samples reach its readers without discovery.
  if (spec.per_robot) {
    writer_robots_.add(w->get_instance_handle(),
                       robot_id ? std::vector<std::string>{*robot_id} : std::vector<std::string>{});
  }
  return Writer(publisher, w, nullptr, &live_handles_);
}

Reader Participant::make_reader(const TopicSpec& spec, Topic* topic, std::unique_ptr<DataReaderListener> owned,
                                DataReaderListener* borrowed) {
  DataReaderListener* listener = owned ? owned.get() : borrowed;
  Subscriber* subscriber = spec.per_robot ? robot_subscriber_ : subscriber_;
  DataReader* r = subscriber->create_datareader_with_profile(topic, spec.reader_profile, listener);
  if (!r) {
    throw DdsError("cannot create reader on " + topic->get_name() + " with profile " + spec.reader_profile +
                   (secured_ ? " (is it granted by this enclave's permissions?)" : ""));
  }
  return Reader(subscriber, r, std::move(owned), &live_handles_);
}

}  // namespace beaconloc::dds
