#pragma once
// A topic's type support that gives each sample twice: read (the type's own, checked as
// CheckedType checks it) and as the bytes it travelled in (CDR with its encapsulation header), so
// that a recorder writes exactly what was on the wire (rosbag2 keeps serialized messages) and
// only what reads. A payload that does not read is refused and counted like CheckedType's.
#include <atomic>
#include <cstdint>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <functional>
#include <vector>

#include "beaconloc/dds/checked_type.hpp"

namespace beaconloc::dds {

template <class PubSubType>
struct RawSample {
  typename PubSubType::type message;
  std::vector<std::uint8_t> cdr;  // the serialized payload, encapsulation header first
};

template <class PubSubType>
class RawCdrType : public eprosima::fastdds::dds::TopicDataType {
 public:
  using type = RawSample<PubSubType>;
  explicit RawCdrType(std::atomic<std::uint64_t>* refused = nullptr) : inner_(refused) {
    // The same name, size and key as the type itself: it matches writers of that type.
    setName(inner_.getName());
    m_typeSize = inner_.m_typeSize;
    m_isGetKeyDefined = inner_.m_isGetKeyDefined;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto& cdr = static_cast<type*>(data)->cdr;
    if (cdr.size() > payload->max_size) return false;
    std::copy(cdr.begin(), cdr.end(), payload->data);
    payload->length = static_cast<std::uint32_t>(cdr.size());
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    auto* sample = static_cast<type*>(data);
    if (!inner_.deserialize(payload, &sample->message)) return false;  // counted there
    sample->cdr.assign(payload->data, payload->data + payload->length);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<type*>(data)->cdr.size()); };
  }
  void* createData() override { return new type(); }
  void deleteData(void* data) override { delete static_cast<type*>(data); }
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool force_md5 = false) override {
    return inner_.getKey(&static_cast<type*>(data)->message, handle, force_md5);
  }

 private:
  CheckedType<PubSubType> inner_;
};

}  // namespace beaconloc::dds
