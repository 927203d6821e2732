// beaconloc serial-sim: the simulator's samples written as receiver hardware sends them on a
// serial line (line_simulator.hpp), for the serial gateway's tests and for trying a gateway
// without hardware: `socat pty,raw,echo=0,link=/tmp/gw pty,raw,echo=0,link=/tmp/sim` makes the line.
#include <atomic>
#include <chrono>
#include <iostream>
#include <thread>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "command.hpp"
#include "line_simulator.hpp"
#include "number_options.hpp"
#include "options.hpp"

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;

class SerialSimCommand : public Command {
 public:
  explicit SerialSimCommand(CLI::App& app)
      : Command(app.add_subcommand(
            "serial-sim",
            "write a simulated robot's TOFs and wheel odometry on a serial device as receiver "
            "hardware does (docs/serial-protocol.md), in real time, with the line's faults")) {
    app_->add_option("--device", o_.device, "the serial device (a pseudo-terminal) to write")->required();
    app_->add_option("--baud", o_.baud, "the line's baud rate");
    app_->add_option("--serial-protocol", protocol_, "beaconloc (our frames) or marvelmind (raw distances)")
        ->check(CLI::IsMember({"beaconloc", "marvelmind"}));
    app_->add_option("--scenario", source_.scenario_file, "scenario YAML (default: the built-in scenario)")
        ->check(CLI::ExistingFile);
    app_->add_option("--seed", seed_, "random seed of the simulated noise (default: the scenario's)");
    app_->add_option("--duration-s", o_.duration_s, "seconds to run (0: until stopped)")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--drift-ppm", o_.drift_ppm, "the module's clock against the host's")
        ->transform(real_in(-1e3, 1e3));
    app_->add_option("--garbage-every-s", o_.garbage_every_s,
                     "random bytes between frames about this often (s)")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--corrupt-every-s", o_.corrupt_every_s,
                     "a frame with a byte flipped about this often (s)")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_flag("--split-frames", o_.split_frames, "write every frame in two pieces a millisecond apart");
    app_->add_option("--stall-at-s", o_.stall_at_s, "the line goes silent at this time (s)")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--stall-s", o_.stall_s, "for this long (s)")->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--truth-out", o_.truth_csv,
                     "ground truth CSV on the host's clock (as the gateway stamps)");
  }
  int execute() override {
    o_.protocol = protocol_ == "marvelmind" ? serial::Protocol::kMarvelmind : serial::Protocol::kBeaconloc;
    LoadedSource source = load_source(source_, seed_);
    o_.seed = source.seed;
    LineSimulator line(o_, *source.source, [] { return dds::wall_clock_ns(); });
    std::atomic<bool> stop{false};
    std::thread watcher([&stop] {
      while (!stop && !dds::wait_for_stop(100ms)) {
      }
      stop = true;
    });
    const LineSimulatorCounts c = line.run(stop);
    stop = true;
    watcher.join();
    std::cout << "serial-sim: " << c.frames << " frames, " << c.samples_intact << " samples intact, "
              << c.garbage_runs << " garbage runs, " << c.corrupted << " corrupted, " << c.dropped_in_stall
              << " dropped in the stall, " << c.dropped_device_gone << " lost while the device was away ("
              << c.reopened << " reopens), " << c.not_sendable << " not sendable\n";
    return 0;
  }

 private:
  LineSimulatorOptions o_;
  std::string protocol_ = "beaconloc";
  SourceChoice source_;
  std::optional<std::uint64_t> seed_;
};

}  // namespace

void add_serial_sim_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<SerialSimCommand>(app));
}

}  // namespace beaconloc::cli
