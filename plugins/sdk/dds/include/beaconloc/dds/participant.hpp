#pragma once
// A DomainParticipant with its publisher and subscriber, created from the XML profiles, and the
// owning handles (Writer, Reader) of the entities it creates. Thin: no logic beyond creating
// entities with named QoS.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/TransportDescriptorInterface.h>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "beaconloc/core/deadline_watch.hpp"
#include "beaconloc/core/participant_id.hpp"
#include "beaconloc/dds/checked_type.hpp"
#include "beaconloc/dds/raw_cdr_type.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "beaconloc/dds/security.hpp"
#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc::dds {

struct DdsOptions {
  int domain_id = 0;
  // The loopback-only profile keeps every packet on the machine (examples/qos/loopback.xml).
  std::string participant_profile = "beaconloc.loopback";
  std::vector<std::string> extra_qos_files;  // loaded after the embedded profiles
  SecurityOptions security;                   // off unless a keystore is given
  // A transport of the caller's in place of the profile's (a test's transport that tampers).
  std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> transport;
};

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads the embedded profiles, then each extra file (each once per process). Throws DdsError
// naming a file that fails, or that defines a profile name already defined (built in, or by an
// earlier file), or one twice: Fast DDS would only log it and keep the first definition.
void load_qos_profiles(const std::vector<std::string>& extra_files);

// What a reader tells its participant besides samples (each member optional):
template <class Msg>
struct ReaderEvents {
  // The topic's deadline (TopicSpec::deadline_ns) passed without a sample of an instance: the
  // misses counted, once per period of silence.
  std::atomic<std::uint64_t>* deadline_misses = nullptr;
  // The instance that missed its deadline, as a sample whose key fields are set (the robot id).
  std::function<void(const Msg& key)> on_deadline_missed;
  std::atomic<std::uint64_t>* writers_lost = nullptr;  // liveliness QoS: a writer died or hung
  // True from a writer's loss of liveliness until a writer is alive again (a writer that leaves
  // cleanly is not lost).
  std::atomic<bool>* lost_and_none_alive = nullptr;
  // A writer of the topic is gone: unmatched (deleted, its participant left or was lost) or its
  // liveliness lost; the id is writer_id() of its samples' SampleInfo::publication_handle.
  std::function<void(const std::string& writer)> on_writer_gone;
  // A writer's liveliness is asserted again after its loss (a stall longer than the lease); also
  // told at its first assertion or sample.
  std::function<void(const std::string& writer)> on_writer_alive;
  // A writer unmatched for good (deleted, its participant left or was dropped), after on_writer_gone.
  std::function<void(const std::string& writer)> on_writer_unmatched;
  // A sample without data: its writer disposed or unregistered the instance (info.instance_state).
  std::function<void(const eprosima::fastdds::dds::SampleInfo& info)> on_instance_ended;
};

// A writer's identity, as the DDS-free code keys it (the hex digits of its GUID).
inline std::string writer_id(const eprosima::fastdds::dds::InstanceHandle_t& publication_handle) {
  std::ostringstream s;
  s << std::hex;
  for (int i = 0; i < 16; ++i) {
    const int octet = publication_handle.value[i];
    s << (octet < 16 ? "0" : "") << octet;
  }
  return s.str();
}

using beaconloc::participant_of_writer;  // core/participant_id.hpp

// The partition a robot's measurements travel in (TopicSpec::per_robot): a gateway's permissions
// grant it its own robot's partition only (scripts/deployment-keys.sh).
inline std::string robot_partition(const std::string& robot_id) { return "robot/" + robot_id; }

template <class Msg, class = void>
struct HasRobotId : std::false_type {};
template <class Msg>
struct HasRobotId<Msg, std::void_t<decltype(std::declval<const Msg&>().robot_id())>> : std::true_type {};

// Which robots each writer of a per-robot topic may speak for: the robots of its partitions, as
// discovery (authenticated and access-checked when secured) told them when it found the writer,
// and this participant's own writers. Told of a remote writer before it is matched (Fast DDS calls
// on_publisher_discovery before pairing), so no sample arrives from a writer it does not know. A
// writer's later change of partitions only narrows its robots; a writer gone is forgotten once
// kRetiredWriters more have gone (its last samples may still be queued).
class WriterRobots : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;
  void add(const eprosima::fastdds::dds::InstanceHandle_t& writer, std::vector<std::string> robots);
  // Whether the writer may publish samples of robot_id: it is in that robot's partition; or, only
  // when unsecured (strict false), it is in no robot partition or not known.
  bool may_speak_for(const eprosima::fastdds::dds::InstanceHandle_t& writer, const std::string& robot_id,
                     bool strict) const;

 private:
  static constexpr std::size_t kRetiredWriters = 1024;
  struct Entry {
    bool partitioned = false;         // in a robot partition when found
    std::vector<std::string> robots;  // those partitions' robots, narrowed by later changes
  };
  mutable std::mutex mutex_;
  std::map<eprosima::fastdds::dds::InstanceHandle_t, Entry> robots_;
  std::deque<eprosima::fastdds::dds::InstanceHandle_t> retired_;  // gone, oldest first
};

// Takes every valid sample a reader has and hands it to a callback with its SampleInfo; keeps
// the topic's deadline per instance (TopicSpec::deadline_ns: a DeadlineWatch checked on a thread
// of its own about four times per period, so a miss is told 1-1.3 periods after the last sample
// taken; a sample its lifespan dropped, or one that could not be decoded, does not count); counts
// writers that lost liveliness, and tells which writers went away.
// The misses are told under the watch's lock, so that a miss is never told after the sample that
// ended it (on_sample runs after the sample renewed the deadline): a participant must not take,
// inside on_deadline_missed, a lock under which it writes a topic it watches itself.
template <class Msg>
class SampleListener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using OnSample = std::function<void(const Msg&, const eprosima::fastdds::dds::SampleInfo&)>;
  // Throws std::logic_error when events ask for deadline misses of a topic without a deadline.
  SampleListener(OnSample on_sample, ReaderEvents<Msg> events, std::int64_t deadline_ns)
      : on_sample_(std::move(on_sample)), events_(std::move(events)) {
    const bool deadline_asked = events_.deadline_misses || events_.on_deadline_missed;
    if (deadline_asked && deadline_ns <= 0) {
      throw std::logic_error("deadline misses asked of a reader whose topic has no deadline");
    }
    if (deadline_asked) {
      watch_.emplace(deadline_ns);
      const auto tick = std::max(std::chrono::milliseconds(1),
                                 std::chrono::duration_cast<std::chrono::milliseconds>(
                                     std::chrono::nanoseconds(deadline_ns / kDeadlineChecksPerPeriod)));
      deadline_checks_ = std::make_unique<PeriodicTask>(tick, [this] { check_deadlines(); });
    }
  }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    Msg m;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) {
        if (watch_) {
          // Disposed, unregistered, or its writers gone: no longer watched, as the QoS drops an
          // instance that is not alive (a dead gateway is told by liveliness instead).
          std::lock_guard<std::mutex> lock(watch_mutex_);
          watch_->forget(info.instance_handle);
        }
        if (events_.on_instance_ended) events_.on_instance_ended(info);
        continue;
      }
      if (watch_) {
        // Fast DDS 2.9's DataReader::get_key_value is unsupported: keep each instance's key.
        std::lock_guard<std::mutex> lock(watch_mutex_);
        watch_->on_sample(info.instance_handle, steady_clock_ns());
        if (events_.on_deadline_missed) keys_.try_emplace(info.instance_handle, m);
      }
      on_sample_(m, info);
    }
  }
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& s) override {
    if (s.current_count_change < 0) {
      if (events_.on_writer_gone) events_.on_writer_gone(writer_id(s.last_publication_handle));
      if (events_.on_writer_unmatched) events_.on_writer_unmatched(writer_id(s.last_publication_handle));
    }
  }
  void on_liveliness_changed(eprosima::fastdds::dds::DataReader*,
                             const eprosima::fastdds::dds::LivelinessChangedStatus& s) override {
    if (events_.writers_lost && s.not_alive_count_change > 0) {
      *events_.writers_lost += static_cast<std::uint64_t>(s.not_alive_count_change);
    }
    if (events_.lost_and_none_alive) {
      if (s.alive_count > 0) {
        *events_.lost_and_none_alive = false;
      } else if (s.not_alive_count_change > 0) {
        *events_.lost_and_none_alive = true;
      }
    }
    if (events_.on_writer_gone && s.not_alive_count_change > 0) {
      events_.on_writer_gone(writer_id(s.last_publication_handle));
    }
    if (events_.on_writer_alive && s.alive_count_change > 0) {
      events_.on_writer_alive(writer_id(s.last_publication_handle));
    }
  }

 private:
  static constexpr int kDeadlineChecksPerPeriod = 4;
  // On the checks' thread: the instances past their deadline, told under the watch's lock.
  void check_deadlines() {
    std::lock_guard<std::mutex> lock(watch_mutex_);
    const std::uint64_t missed =
        watch_->expire(steady_clock_ns(), [&](const eprosima::fastdds::dds::InstanceHandle_t& handle) {
          if (!events_.on_deadline_missed) return;
          const auto it = keys_.find(handle);
          if (it != keys_.end()) events_.on_deadline_missed(it->second);
        });
    if (events_.deadline_misses) *events_.deadline_misses += missed;
  }

  OnSample on_sample_;
  ReaderEvents<Msg> events_;
  std::mutex watch_mutex_;
  std::optional<DeadlineWatch<eprosima::fastdds::dds::InstanceHandle_t>> watch_;  // with a deadline
  std::map<eprosima::fastdds::dds::InstanceHandle_t, Msg> keys_;  // a sample of each instance seen
  std::unique_ptr<PeriodicTask> deadline_checks_;  // last: stops before what it uses goes
};

// Waits until every writer has at least one matched reader; false on timeout.
bool wait_for_matched_readers(const std::vector<eprosima::fastdds::dds::DataWriter*>& writers,
                              std::chrono::milliseconds timeout);

// Deletes a DataWriter from its publisher, a DataReader from its subscriber (participant.cpp).
void delete_entity(eprosima::fastdds::dds::Publisher* parent, eprosima::fastdds::dds::DataWriter* entity);
void delete_entity(eprosima::fastdds::dds::Subscriber* parent, eprosima::fastdds::dds::DataReader* entity);

// A DataWriter or DataReader this code owns (RAII): deleted when its handle goes, a reader after
// any callback under way has returned, and then its listener (when the handle owns it). A class
// declares its participant first, the state its callbacks use next, and its handles last, so that
// the readers stop before anything they use is destroyed, with no destructor to write. Move-only.
// A handle must not outlive its participant: ~Participant aborts, naming it, if one does.
template <class Parent, class Entity, class Listener>
class OwnedEntity {
 public:
  OwnedEntity() = default;
  OwnedEntity(OwnedEntity&& other) noexcept { *this = std::move(other); }
  OwnedEntity& operator=(OwnedEntity&& other) noexcept {
    if (this != &other) {
      reset();
      parent_ = std::exchange(other.parent_, nullptr);
      entity_ = std::exchange(other.entity_, nullptr);
      listener_ = std::move(other.listener_);
      live_ = std::exchange(other.live_, nullptr);
    }
    return *this;
  }
  OwnedEntity(const OwnedEntity&) = delete;
  OwnedEntity& operator=(const OwnedEntity&) = delete;
  ~OwnedEntity() { reset(); }
  Entity* get() const { return entity_; }
  Entity* operator->() const { return entity_; }
  explicit operator bool() const { return entity_ != nullptr; }
  // Deletes the entity (a reader waits for a callback under way: after this no callback runs),
  // then the listener the handle owns, which that callback may have used.
  void reset() {
    if (entity_) {
      delete_entity(parent_, entity_);
      entity_ = nullptr;
      --*live_;
    }
    listener_.reset();
  }

 private:
  friend class Participant;
  OwnedEntity(Parent* parent, Entity* entity, std::unique_ptr<Listener> listener, std::atomic<int>* live)
      : parent_(parent), entity_(entity), listener_(std::move(listener)), live_(live) {
    ++*live_;
  }
  Parent* parent_ = nullptr;
  Entity* entity_ = nullptr;
  std::unique_ptr<Listener> listener_;  // when the handle owns it
  std::atomic<int>* live_ = nullptr;    // the participant's count of handles
};

using Writer = OwnedEntity<eprosima::fastdds::dds::Publisher, eprosima::fastdds::dds::DataWriter,
                           eprosima::fastdds::dds::DataWriterListener>;
using Reader = OwnedEntity<eprosima::fastdds::dds::Subscriber, eprosima::fastdds::dds::DataReader,
                           eprosima::fastdds::dds::DataReaderListener>;

class Participant {
 public:
  Participant(const DdsOptions& options, const std::string& name);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // A writer in the default partition. Of a per-robot topic, only unsecured participants read it
  // (a tool or benchmark writing many robots): a robot's own writer is robot_writer.
  template <class PubSubType>
  [[nodiscard]] Writer writer(const TopicSpec& spec, eprosima::fastdds::dds::DataWriterListener* listener = nullptr) {
    return make_writer(spec, topic(spec.name, new CheckedType<PubSubType>(&undecodable_)), listener, nullptr);
  }
  // A writer of one robot's samples of a per-robot topic, in that robot's partition.
  template <class PubSubType>
  [[nodiscard]] Writer robot_writer(const TopicSpec& spec, const std::string& robot_id) {
    if (!spec.per_robot) throw std::logic_error(std::string("topic ") + spec.name + " is not per robot");
    return make_writer(spec, topic(spec.name, new CheckedType<PubSubType>(&undecodable_)), nullptr, &robot_id);
  }
  // Subscribes with the topic's reader profile; on_sample runs on the reader's thread for each
  // valid sample, until the handle goes (which owns the listener).
  template <class PubSubType>
  [[nodiscard]] Reader subscribe(const TopicSpec& spec, std::function<void(const typename PubSubType::type&)> on_sample,
                                 std::atomic<std::uint64_t>* deadline_misses = nullptr) {
    ReaderEvents<typename PubSubType::type> events;
    events.deadline_misses = deadline_misses;
    return subscribe<PubSubType>(spec, std::move(on_sample), std::move(events));
  }
  template <class PubSubType>
  [[nodiscard]] Reader subscribe(const TopicSpec& spec, std::function<void(const typename PubSubType::type&)> on_sample,
                                 ReaderEvents<typename PubSubType::type> events) {
    return subscribe_with_info<PubSubType>(
        spec,
        [on_sample = std::move(on_sample)](const typename PubSubType::type& m,
                                           const eprosima::fastdds::dds::SampleInfo&) { on_sample(m); },
        std::move(events));
  }
  // The same, with each sample's SampleInfo (its writer: publication_handle).
  // A per-robot topic's sample is taken only from a writer that may speak for its robot
  // (WriterRobots); the others are counted (samples_for_another_robot) and dropped.
  template <class PubSubType>
  [[nodiscard]] Reader subscribe_with_info(const TopicSpec& spec,
                                           typename SampleListener<typename PubSubType::type>::OnSample on_sample,
                                           ReaderEvents<typename PubSubType::type> events = {}) {
    using Msg = typename PubSubType::type;
    if constexpr (HasRobotId<Msg>::value) {
      if (spec.per_robot) {
        on_sample = [this, inner = std::move(on_sample)](const Msg& m,
                                                          const eprosima::fastdds::dds::SampleInfo& info) {
          if (!writer_robots_.may_speak_for(info.publication_handle, m.robot_id(), secured_)) {
            ++samples_for_another_robot_;
            return;
          }
          inner(m, info);
        };
      }
    } else if (spec.per_robot) {
      throw std::logic_error(std::string("per-robot topic ") + spec.name + " of a type without robot_id");
    }
    return make_reader(spec, topic(spec.name, new CheckedType<PubSubType>(&undecodable_)),
                       std::make_unique<SampleListener<Msg>>(std::move(on_sample), std::move(events),
                                                             spec.deadline_ns),
                       nullptr);
  }
  // Each sample read and as the bytes it travelled in (raw_cdr_type.hpp): a recorder's reader of a
  // topic that is not per robot (the ROS 2 ones).
  template <class PubSubType>
  [[nodiscard]] Reader subscribe_raw(const TopicSpec& spec,
                                     typename SampleListener<RawSample<PubSubType>>::OnSample on_sample) {
    if (spec.per_robot) throw std::logic_error(std::string("per-robot topic ") + spec.name + " needs subscribe");
    return make_reader(spec, topic(spec.name, new RawCdrType<PubSubType>(&undecodable_)),
                       std::make_unique<SampleListener<RawSample<PubSubType>>>(
                           std::move(on_sample), ReaderEvents<RawSample<PubSubType>>{}, spec.deadline_ns),
                       nullptr);
  }
  // A reader with a listener of the caller's, which must outlive the handle (declared before it).
  // The topic's deadline (spec.deadline_ns) is the listener's to keep: this keeps none.
  // Not for a per-robot topic (std::logic_error): its samples' robots are checked by subscribe.
  template <class PubSubType>
  [[nodiscard]] Reader reader(const TopicSpec& spec, eprosima::fastdds::dds::DataReaderListener* listener) {
    if (spec.per_robot) throw std::logic_error(std::string("per-robot topic ") + spec.name + " needs subscribe");
    return make_reader(spec, topic(spec.name, new CheckedType<PubSubType>(&undecodable_)), nullptr, listener);
  }
  const std::string& name() const { return name_; }
  // Samples whose payload could not be read, on any topic (Fast DDS dropped them).
  std::uint64_t undecodable_samples() const { return undecodable_.load(); }
  // Samples of a per-robot topic from a writer that may not speak for their robot (dropped).
  std::uint64_t samples_for_another_robot() const { return samples_for_another_robot_.load(); }
  bool secured() const { return secured_; }

 private:
  eprosima::fastdds::dds::Topic* topic(const std::string& name, eprosima::fastdds::dds::TopicDataType* type);
  // robot_id: the robot whose partition the writer is in; null: the default partition.
  Writer make_writer(const TopicSpec& spec, eprosima::fastdds::dds::Topic* topic,
                     eprosima::fastdds::dds::DataWriterListener* l, const std::string* robot_id);
  // owned: the listener the handle keeps; else borrowed, the caller's.
  Reader make_reader(const TopicSpec& spec, eprosima::fastdds::dds::Topic* topic,
                     std::unique_ptr<eprosima::fastdds::dds::DataReaderListener> owned,
                     eprosima::fastdds::dds::DataReaderListener* borrowed);
  eprosima::fastdds::dds::Publisher* robot_publisher(const std::string& robot_id);

  std::string name_;
  bool secured_ = false;
  std::atomic<std::uint64_t> undecodable_{0};  // counted by the types this participant registers
  std::atomic<std::uint64_t> samples_for_another_robot_{0};
  WriterRobots writer_robots_;  // before the participant: its listener
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  // The readers of per-robot topics: every robot's partition, and (unsecured only) the default one.
  eprosima::fastdds::dds::Subscriber* robot_subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Publisher*> robot_publishers_;  // by robot id
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::atomic<int> live_handles_{0};  // Writers and Readers not yet reset
};

// Waits until every writer has at least one matched reader; false on timeout.
inline bool wait_for_matched_readers(std::initializer_list<std::reference_wrapper<const Writer>> writers,
                                     std::chrono::milliseconds timeout) {
  std::vector<eprosima::fastdds::dds::DataWriter*> raw;
  for (const Writer& w : writers) raw.push_back(w.get());
  return wait_for_matched_readers(raw, timeout);
}

}  // namespace beaconloc::dds
