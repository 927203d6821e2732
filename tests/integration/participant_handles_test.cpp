// The DDS entities are owned (issue 14, item 8): a dds::Reader or dds::Writer deletes its entity
// when it goes, a reader only after the callback under way has returned, so that a class that
// declares its handles last needs no destructor to stop its callbacks; and a handle that would
// outlive its participant is a programming error that aborts, naming the participant.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "beaconloc/dds/first_sample_watch.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "participants_test.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class ParticipantHandles : public ParticipantsTest {};

TEST_F(ParticipantHandles, AReaderThatGoesWaitsForItsCallbackUnderWayAndNoneRunsAfter) {
  dds::Participant bus(dds_, "test.handles");
  std::atomic<int> started{0}, finished{0};
  dds::Writer writer = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);
  dds::Reader reader = bus.subscribe<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic, [&](const msg::BeaconRange&) {
    ++started;
    std::this_thread::sleep_for(300ms);  // long enough for the reset below to come during it
    ++finished;
  });
  ASSERT_TRUE(dds::wait_for_matched_readers({writer}, scaled(10s)));
  msg::BeaconRange m;
  m.robot_id("r");
  m.stamp_ns(dds::wall_clock_ns());
  // Written from another thread: whether delivery runs on the writer's thread or the reader's,
  // the callback is under way while this thread resets the reader.
  std::thread write([&] { writer->write(&m); });
  const bool under_way = eventually([&] { return started.load() == 1; }, scaled(10s));
  if (under_way) reader.reset();
  const int finished_at_reset = finished.load();
  write.join();
  ASSERT_TRUE(under_way) << "the sample never reached the reader";
  EXPECT_EQ(finished_at_reset, 1) << "the reader went while its callback was still running";
  EXPECT_FALSE(reader);
  m.stamp_ns(dds::wall_clock_ns());
  writer->write(&m);
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(started.load(), 1) << "a callback ran after its reader went";
}

TEST_F(ParticipantHandles, AMovedHandleKeepsTheEntityAndTheOneMovedFromHasNone) {
  dds::Participant bus(dds_, "test.handles");
  dds::Writer first = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);
  eprosima::fastdds::dds::DataWriter* const entity = first.get();
  dds::Writer second = std::move(first);
  EXPECT_FALSE(first);
  EXPECT_EQ(second.get(), entity);
  msg::BeaconRange m;
  m.robot_id("r");
  m.stamp_ns(dds::wall_clock_ns());
  EXPECT_TRUE(second->write(&m));
  second = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);  // the first entity deleted
  EXPECT_NE(second.get(), nullptr);
}

TEST_F(ParticipantHandles, AHandleThatWouldOutliveItsParticipantAbortsNamingIt) {
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";  // DDS runs threads of its own
  // Over UDP on loopback only: the child aborts with its participant alive, and a shared-memory
  // transport would leave its segments in /dev/shm.
  dds::DdsOptions options = dds_;
  options.participant_profile = "beaconloc.loopback_udp";
  EXPECT_DEATH(
      {
        dds::Writer outliving;
        {
          dds::Participant bus(options, "test.outlived");
          outliving = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);
        }
      },
      "participant 'test.outlived' destroyed before 1 of its readers or writers");
}

// A reader that must hear (the beacon map) and stays mute while matched (Fast DDS 2.9's secured
// pair that never completes its key exchange; here, a writer that writes nothing) is recreated
// after FirstSampleWatch::kMuteAfterNs, counted; once it has heard a sample it is left alone.
TEST_F(ParticipantHandles, AMuteReaderOfTheBeaconMapIsRecreatedUntilItHears) {
  dds::Participant bus(dds_, "test.first_sample");
  dds::Writer writer = bus.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  std::atomic<int> maps{0};
  dds::FirstSampleWatch watch([&](std::function<void()> heard) {
    return bus.subscribe<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, [&, heard](const msg::BeaconMap&) {
      heard();
      ++maps;
    });
  });
  ASSERT_TRUE(dds::wait_for_matched_readers({writer}, scaled(10s)));
  EXPECT_TRUE(eventually([&] { return watch.recreated() >= 1; }, scaled(15s))) << "a mute reader was kept";
  ASSERT_TRUE(dds::wait_for_matched_readers({writer}, scaled(10s)));  // the new reader
  msg::BeaconMap m;
  m.frame_id("map");
  ASSERT_TRUE(writer->write(&m));
  ASSERT_TRUE(eventually([&] { return maps.load() >= 1; }, scaled(10s)));
  const std::uint64_t after_hearing = watch.recreated();
  std::this_thread::sleep_for(std::chrono::nanoseconds(2 * dds::FirstSampleWatch::kMuteAfterNs));
  EXPECT_EQ(watch.recreated(), after_hearing) << "a reader that heard was recreated";
}

}  // namespace
}  // namespace beaconloc::testing
