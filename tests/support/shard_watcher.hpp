#pragma once
// The live localizer shards of a domain, as their announcements (LocalizerShard) and its
// liveliness tell: the shard tests and the discovery benchmark watch them.
#include <beaconlocPubSubTypes.h>

#include <mutex>
#include <set>
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc::testing {

// The live shards, as their announcements (LocalizerShard) and their liveliness tell: a shard
// lost is live again once its liveliness is.
class ShardWatcher {
 public:
  explicit ShardWatcher(const dds::DdsOptions& dds) : participant_(dds, "beaconloc.test.shards") {
    dds::ReaderEvents<msg::LocalizerShard> events;
    events.on_writer_gone = [this](const std::string& writer) {
      std::lock_guard<std::mutex> lock(mutex_);
      live_.erase(writer);
    };
    events.on_writer_alive = [this](const std::string& writer) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (announced_.count(writer)) live_.insert(writer);
    };
    events.on_writer_unmatched = [this](const std::string& writer) {
      std::lock_guard<std::mutex> lock(mutex_);
      announced_.erase(writer);
    };
    reader_ = participant_.subscribe_with_info<msg::LocalizerShardPubSubType>(
        dds::kLocalizerShardTopic,
        [this](const msg::LocalizerShard&, const eprosima::fastdds::dds::SampleInfo& info) {
          std::lock_guard<std::mutex> lock(mutex_);
          announced_.insert(dds::writer_id(info.publication_handle));
          live_.insert(dds::writer_id(info.publication_handle));
        },
        events);
  }
  std::set<std::string> live() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return live_;
  }

 private:
  mutable std::mutex mutex_;
  std::set<std::string> live_;       // announcement writer ids
  std::set<std::string> announced_;  // of the shards not gone for good
  dds::Participant participant_;
  dds::Reader reader_;
};

}  // namespace beaconloc::testing
