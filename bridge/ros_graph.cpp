#include "ros_graph.hpp"

#include <algorithm>
#include <cctype>

namespace beaconloc::bridge {

std::string ros_node_name(const std::string& robot_id) {
  std::string name = "beaconloc_bridge_" + robot_id;
  std::replace_if(
      name.begin(), name.end(),
      [](char c) { return !std::isalnum(static_cast<unsigned char>(c)) && c != '_'; }, '_');
  return name;
}

rmw_dds_common::msg::Gid to_gid(const eprosima::fastrtps::rtps::GUID_t& guid) {
  rmw_dds_common::msg::Gid gid;
  auto& data = gid.data();
  static_assert(std::tuple_size<std::remove_reference_t<decltype(data)>>::value >=
                    eprosima::fastrtps::rtps::GuidPrefix_t::size + eprosima::fastrtps::rtps::EntityId_t::size,
                "a GID holds a whole GUID");
  data.fill(0);
  const auto after_prefix =
      std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), data.begin());
  std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value), after_prefix);
  return gid;
}

rmw_dds_common::msg::ParticipantEntitiesInfo node_entities(
    const eprosima::fastrtps::rtps::GUID_t& participant, const std::string& ros_namespace,
    const std::string& node_name, const std::vector<eprosima::fastrtps::rtps::GUID_t>& readers,
    const std::vector<eprosima::fastrtps::rtps::GUID_t>& writers) {
  rmw_dds_common::msg::NodeEntitiesInfo node;
  node.node_namespace("/" + ros_namespace);
  node.node_name(node_name);
  for (const auto& r : readers) node.reader_gid_seq().push_back(to_gid(r));
  for (const auto& w : writers) node.writer_gid_seq().push_back(to_gid(w));
  rmw_dds_common::msg::ParticipantEntitiesInfo info;
  info.gid(to_gid(participant));
  info.node_entities_info_seq().push_back(std::move(node));
  return info;
}

}  // namespace beaconloc::bridge
