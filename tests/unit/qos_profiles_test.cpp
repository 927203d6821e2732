// QoS files (--qos, dds::load_qos_profiles): a file that redefines a built-in profile, or defines
// one twice, is refused naming the profile (Fast DDS 2.9 only logs it, returns RETCODE_OK and
// keeps the first definition). Nothing here creates a participant.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <tinyxml2.h>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/dds/participant.hpp"

namespace beaconloc {
namespace {

std::string write_qos(const std::string& name, const std::string& profiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("beaconloc_qos_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << "<?xml version=\"1.0\"?>\n"
                         "<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\">\n"
                      << profiles << "</profiles>\n";
  return path;
}

std::string error_of(const std::string& file) {
  try {
    dds::load_qos_profiles({file});
  } catch (const dds::DdsError& e) {
    return e.what();
  }
  return "";
}

TEST(QosProfiles, AFileThatRedefinesAProfileIsRefusedNamingIt) {
  const std::string loopback =
      write_qos("loopback.xml", "  <participant profile_name=\"beaconloc.loopback\"><rtps/></participant>\n");
  EXPECT_EQ(error_of(loopback),
            "QoS file '" + loopback +
                "':3: participant 'beaconloc.loopback' is already defined (built in, or by an "
                "earlier file): Fast DDS would keep the first definition; give the profile a "
                "name of its own");
  const std::string writer =
      write_qos("writer.xml", "  <data_writer profile_name=\"raw_tof.writer\"><qos/></data_writer>\n");
  EXPECT_NE(error_of(writer).find("':3: data_writer 'raw_tof.writer' is already defined"), std::string::npos);
  const std::string twice = write_qos("twice.xml",
                                      "  <data_reader profile_name=\"mine.reader\"><qos/></data_reader>\n"
                                      "  <subscriber profile_name=\"mine.reader\"><qos/></subscriber>\n");
  EXPECT_NE(error_of(twice).find("':4: subscriber 'mine.reader' is defined twice in this file"),
            std::string::npos)
      << error_of(twice);
  // A file of new names loads, once per process however many participants ask for it; another
  // file may not take its names.
  const std::string mine =
      write_qos("mine.xml", "  <participant profile_name=\"test.mine\"><rtps/></participant>\n");
  EXPECT_EQ(error_of(mine), "");
  EXPECT_EQ(error_of(mine), "");
  const std::string copy =
      write_qos("copy.xml", "  <participant profile_name=\"test.mine\"><rtps/></participant>\n");
  EXPECT_NE(error_of(copy).find("participant 'test.mine' is already defined"), std::string::npos);
  std::filesystem::remove_all(std::filesystem::path(mine).parent_path());
}

// The horizon is one fact (core/limits.hpp); the QoS file cannot name it, so this holds the raw_tof
// and beacon_range lifespans, writers and readers, to it.
TEST(QosProfiles, TheMeasurementLifespansAreTheHorizon) {
  tinyxml2::XMLDocument doc;
  const std::string file = std::string(BEACONLOC_SOURCE_DIR) + "/examples/qos/topics.xml";
  ASSERT_EQ(doc.LoadFile(file.c_str()), tinyxml2::XML_SUCCESS) << file;
  int checked = 0;
  const tinyxml2::XMLElement* profiles = doc.RootElement()->FirstChildElement("profiles");
  ASSERT_NE(profiles, nullptr) << file;
  for (const tinyxml2::XMLElement* e = profiles->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const char* name = e->Attribute("profile_name");
    if (!name) continue;
    const std::string profile = name;
    if (profile.rfind("raw_tof.", 0) != 0 && profile.rfind("beacon_range.", 0) != 0) continue;
    const tinyxml2::XMLElement* qos = e->FirstChildElement("qos");
    const tinyxml2::XMLElement* lifespan = qos ? qos->FirstChildElement("lifespan") : nullptr;
    const tinyxml2::XMLElement* duration = lifespan ? lifespan->FirstChildElement("duration") : nullptr;
    ASSERT_NE(duration, nullptr) << profile << " has no lifespan";
    const tinyxml2::XMLElement* sec = duration->FirstChildElement("sec");
    const tinyxml2::XMLElement* nanosec = duration->FirstChildElement("nanosec");
    ASSERT_TRUE(sec && nanosec) << profile << ": a lifespan without sec and nanosec";
    const StampNs lifespan_ns = sec->Int64Text() * kNsPerSecond + nanosec->Int64Text();
    EXPECT_EQ(lifespan_ns, kMeasurementHorizonNs) << profile;
    ++checked;
  }
  EXPECT_EQ(checked, 4);  // raw_tof and beacon_range, writer and reader
}

// The robot-keyed topics' deadlines are their readers' (dds::TopicSpec::deadline_ns): a deadline
// QoS in a profile would bring back Fast DDS 2.9's look through every robot's instance on each
// sample, and be a second place for the same period.
TEST(QosProfiles, NoProfileSetsADeadline) {
  for (const char* file : {"/examples/qos/topics.xml", "/benchmarks/fleet/fleet_feeder_qos.xml"}) {
    tinyxml2::XMLDocument doc;
    const std::string path = std::string(BEACONLOC_SOURCE_DIR) + file;
    ASSERT_EQ(doc.LoadFile(path.c_str()), tinyxml2::XML_SUCCESS) << path;
    const tinyxml2::XMLElement* profiles = doc.RootElement()->FirstChildElement("profiles");
    ASSERT_NE(profiles, nullptr) << path;
    int profiles_read = 0;
    for (const tinyxml2::XMLElement* e = profiles->FirstChildElement(); e; e = e->NextSiblingElement()) {
      ++profiles_read;
      const tinyxml2::XMLElement* qos = e->FirstChildElement("qos");
      EXPECT_TRUE(!qos || !qos->FirstChildElement("deadline")) << path << ": " << e->Attribute("profile_name");
    }
    EXPECT_GT(profiles_read, 0) << path;
  }
  EXPECT_EQ(dds::kOdometryTopic.deadline_ns, 50 * kNsPerMillisecond);
  EXPECT_EQ(dds::kRawTofTopic.deadline_ns, 2 * 200 * kNsPerMillisecond);  // two beacon slots
}

}  // namespace
}  // namespace beaconloc
