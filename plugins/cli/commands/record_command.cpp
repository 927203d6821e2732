// beaconloc record: what the bus carries for one robot, written as a recording that
// `beaconloc run --replay` replays (bus_recorder.hpp), and the ROS 2 topics its bridge speaks as
// a rosbag2 bag that `ros2 bag info` and `ros2 bag play` open (ros2_bag_recorder.hpp).
#include <chrono>
#include <filesystem>
#include <iostream>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "bus_recorder.hpp"
#include "command.hpp"
#include "number_options.hpp"
#include "options.hpp"
#include "ros2_bag_recorder.hpp"

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;

class RecordCommand : public Command {
 public:
  explicit RecordCommand(CLI::App& app)
      : Command(
            app.add_subcommand("record",
                               "record one robot's samples, beacon map and poses from the bus (a recording "
                               "`run --replay` replays) and its bridge's ROS 2 topics (a rosbag2 bag)")) {
    dds_option_set(dds_).add_to(app_);
    app_->add_option("--out", out_dir_, "directory to write (must not hold a recording already)")->required();
    app_->add_option("--robot", bus_.robot_id, "the robot whose samples and poses are recorded");
    app_->add_option("--namespace", bag_.ros_namespace,
                     "the ROS 2 namespace of its bridge (as bridge --namespace)");
    app_->add_option(
        "--receivers", receivers_.receivers,
        "the robot's receivers, x:y[,x:y...] (m), written for the replay (the bus does not carry them)");
    app_->add_option("--receiver-height-m", receivers_.receiver_height_m, "receivers' height above the floor")
        ->transform(real_in(-kMaxReceiverOffsetM, kMaxReceiverOffsetM));
    app_->add_flag("--no-bag", no_bag_, "no rosbag2 bag: the bus's samples only");
    app_->add_option("--duration-s", duration_s_, "stop after this many seconds (0: until stopped)")
        ->transform(real_in(0.0, kMaxDurationS));
  }
  int execute() override {
    namespace fs = std::filesystem;
    if (fs::exists(out_dir_) && !fs::is_empty(out_dir_)) {
      throw std::invalid_argument("--out '" + out_dir_ +
                                  "' is not empty: a recording is never written over another");
    }
    bus_.out_dir = out_dir_;
    bus_.receivers = receivers_.config().receivers;
    bag_.bag_dir = out_dir_ + "/rosbag2";
    BusRecorder bus(dds_, bus_);
    std::unique_ptr<Ros2BagRecorder> bag;
    if (!no_bag_) bag = std::make_unique<Ros2BagRecorder>(dds_, bag_);
    std::cerr << "beaconloc record: robot " << bus_.robot_id << " into " << out_dir_
              << (bag ? " (and rosbag2/)" : "") << "; stop with Ctrl-C\n";
    const auto start = std::chrono::steady_clock::now();
    const auto limit = std::chrono::duration<double>(duration_s_);
    while (!dds::wait_for_stop(100ms)) {
      if (duration_s_ > 0.0 && std::chrono::steady_clock::now() - start >= limit) break;
    }
    if (bag) bag->close();
    return report(bus, bag.get());
  }

 private:
  // What was written; a recording of nothing is a failure that says why.
  int report(const BusRecorder& bus, const Ros2BagRecorder* bag) const {
    for (const auto& [file, n] : bus.written()) std::cout << "  " << file << ": " << n << " rows\n";
    for (const auto& [reason, n] : bus.refused()) std::cout << "  refused " << reason << ": " << n << "\n";
    std::uint64_t messages = 0;
    if (bag) {
      for (const auto& [topic, n] : bag->written()) {
        std::cout << "  rosbag2 " << topic << ": " << n << " messages\n";
        messages += n;
      }
      if (bag->undecodable())
        std::cout << "  refused undecodable ROS 2 messages: " << bag->undecodable() << "\n";
      if (bag->failed_writes()) std::cout << "  rosbag2 writes failed: " << bag->failed_writes() << "\n";
    }
    const bool failed_writes = bus.refused().count("write_failed") || (bag && bag->failed_writes());
    if (failed_writes) {
      std::cerr
          << "beaconloc record: some rows could not be written (see above); the recording is incomplete\n";
      return 1;
    }
    if (bus.samples_written() == 0 && messages == 0) {
      std::cerr << "beaconloc record: nothing recorded: no sample of robot " << bus_.robot_id
                << " and no ROS 2 message on domain " << dds_.domain_id
                << " (is the pipeline running there?)\n";
      return 1;
    }
    return 0;
  }

  dds::DdsOptions dds_;
  std::string out_dir_;
  BusRecorderOptions bus_;
  Ros2BagOptions bag_;
  LocalizerSettings receivers_;  // its receivers only
  bool no_bag_ = false;
  double duration_s_ = 0.0;
};

}  // namespace

void add_record_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<RecordCommand>(app));
}

}  // namespace beaconloc::cli
