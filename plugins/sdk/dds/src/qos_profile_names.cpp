#include "qos_profile_names.hpp"

#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <tinyxml2.h>

#include <cstring>
#include <vector>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc::dds {
namespace {

using eprosima::fastrtps::xmlparser::XMLP_ret;
using eprosima::fastrtps::xmlparser::XMLProfileManager;

struct Definition {
  std::string kind;  // the namespace of its name: Fast DDS keeps writers and publishers together
  std::string element;
  std::string name;
  int line;
};

// The kind of a profile element's name, or nullptr for elements that define none.
const char* kind_of(const char* element) {
  for (const auto& [e, kind] :
       std::initializer_list<std::pair<const char*, const char*>>{{"participant", "participant"},
                                                                  {"data_writer", "writer"},
                                                                  {"publisher", "writer"},
                                                                  {"data_reader", "reader"},
                                                                  {"subscriber", "reader"},
                                                                  {"topic", "topic"}}) {
    if (std::strcmp(element, e) == 0) return kind;
  }
  return nullptr;
}

// The definitions of one <profiles> element.
void collect(const tinyxml2::XMLElement& profiles, std::vector<Definition>& out) {
  for (auto* e = profiles.FirstChildElement(); e; e = e->NextSiblingElement()) {
    if (std::strcmp(e->Name(), "transport_descriptors") == 0) {
      for (auto* t = e->FirstChildElement("transport_descriptor"); t;
           t = t->NextSiblingElement("transport_descriptor")) {
        const auto* id = t->FirstChildElement("transport_id");
        if (id && id->GetText())
          out.push_back({"transport", "transport_id", id->GetText(), id->GetLineNum()});
      }
      continue;
    }
    const char* kind = kind_of(e->Name());
    const char* name = e->Attribute("profile_name");
    if (kind && name) out.push_back({kind, e->Name(), name, e->GetLineNum()});
  }
}

// Fast DDS already holds this name (its default profiles file, loaded before ours).
bool known_to_fast_dds(const Definition& d) {
  if (d.kind == "participant") {
    eprosima::fastrtps::ParticipantAttributes a;
    return XMLProfileManager::fillParticipantAttributes(d.name, a, false) == XMLP_ret::XML_OK;
  }
  if (d.kind == "writer") {
    eprosima::fastrtps::PublisherAttributes a;
    return XMLProfileManager::fillPublisherAttributes(d.name, a, false) == XMLP_ret::XML_OK;
  }
  if (d.kind == "reader") {
    eprosima::fastrtps::SubscriberAttributes a;
    return XMLProfileManager::fillSubscriberAttributes(d.name, a, false) == XMLP_ret::XML_OK;
  }
  if (d.kind == "transport") return XMLProfileManager::getTransportById(d.name) != nullptr;
  return false;  // topics: no quiet look-up; the names added here are checked all the same
}

}  // namespace

void QosProfileNames::add(const std::string& xml, const std::string& origin) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS || !doc.RootElement())
    throw DdsError(origin + " is not a valid Fast DDS profiles file (not XML)");
  // <profiles> at the root, or inside <dds>.
  std::vector<Definition> defined;
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (std::strcmp(root->Name(), "profiles") == 0) collect(*root, defined);
  if (std::strcmp(root->Name(), "dds") == 0) {
    for (auto* p = root->FirstChildElement("profiles"); p; p = p->NextSiblingElement("profiles"))
      collect(*p, defined);
  }
  std::set<std::pair<std::string, std::string>> here;
  for (const auto& d : defined) {
    const auto key = std::make_pair(d.kind, d.name);
    const bool again = !here.insert(key).second;
    if (again || defined_.count(key) || known_to_fast_dds(d)) {
      throw DdsError(
          origin + ":" + std::to_string(d.line) + ": " + d.element + " '" + d.name + "' is " +
          (again ? "defined twice in this file" : "already defined (built in, or by an earlier file)") +
          ": Fast DDS would keep the first definition; give the profile a name of its own");
    }
  }
  defined_.insert(here.begin(), here.end());
}

}  // namespace beaconloc::dds
