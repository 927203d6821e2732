#pragma once
// Receiver hardware, simulated: a source's samples (the simulator's) written as a receiver module
// would send them on a serial line (docs/serial-protocol.md), in real time, with the module's own
// clock (its counter starting anywhere, drifting), and with the line's faults on request:
// garbage between frames, corrupted frames, frames split across writes, a stall. For the serial
// gateway's tests (`beaconloc serial-sim`, on a pseudo-terminal) and for trying a gateway without
// hardware. The truth is written on the host's clock, as the gateway stamps. DDS-free.
#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include "frames.hpp"
#include "serial_port.hpp"
#include "source.hpp"

namespace beaconloc {

struct LineSimulatorOptions {
  std::string device;
  std::uint32_t baud = 115200;
  serial::Protocol protocol = serial::Protocol::kBeaconloc;
  double duration_s = 0.0;  // of source time; 0: until stopped
  std::uint64_t seed = 1;   // of the faults and the device's counter
  double drift_ppm = 0.0;   // the module's crystal against the host's clock
  // Faults: garbage (1..40 random bytes) and a corrupted frame (one byte flipped) about this often
  // (0: never); every frame written in two or three pieces a millisecond apart; the line silent
  // for stall_s from stall_at_s (what the module measures meanwhile is lost).
  double garbage_every_s = 0.0;
  double corrupt_every_s = 0.0;
  bool split_frames = false;
  double stall_at_s = -1.0;
  double stall_s = 0.0;
  std::string truth_csv;  // stamp_ns,x_m,y_m,yaw_rad on the host's clock, when not empty
};

struct LineSimulatorCounts {
  std::uint64_t frames = 0;
  std::uint64_t samples_intact = 0;  // TOF (or distance) and odometry frames written whole and uncorrupted
  std::uint64_t garbage_runs = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t dropped_in_stall = 0;
  std::uint64_t dropped_device_gone = 0;  // written while the device was away or nobody read it
  std::uint64_t reopened = 0;
  std::uint64_t not_sendable =
      0;  // a sample the protocol cannot carry (a TOF beyond 4.29 s, a beacon id > 65535)
};

class LineSimulator {
 public:
  using Clock = std::function<StampNs()>;
  // Throws std::runtime_error naming the device when it cannot be opened.
  LineSimulator(LineSimulatorOptions options, Source& source, Clock now);
  // Writes until the source's duration is done or stop is set.
  LineSimulatorCounts run(const std::atomic<bool>& stop);

 private:
  std::uint32_t device_counter(StampNs source_ns) const;
  // sample: a TOF, distance or odometry frame (not a heartbeat).
  void send(const std::vector<std::uint8_t>& frame, StampNs source_ns, bool sample,
            const std::atomic<bool>& stop);
  // False when the device went away, a stop came, or nobody read the line for a second, before
  // every byte was written (counted dropped_device_gone).
  bool write_all(const std::uint8_t* data, std::size_t size, const std::atomic<bool>& stop);
  // Distances frames carry one slot each: one sample per frame for either protocol.
  void frames_of(const SourceEvent& e, std::vector<std::vector<std::uint8_t>>& out);
  bool stalled(StampNs source_ns) const;

  LineSimulatorOptions options_;
  Source& source_;
  Clock now_;
  serial::SerialPort port_;
  std::mt19937_64 random_;
  std::uint64_t counter_start_ = 0;  // the module's counter at source time 0
  StampNs host_start_ns_ = 0;        // the host's time at source time 0
  std::uint8_t sequence_ = 0;
  std::ofstream truth_;
  LineSimulatorCounts counts_;
};

}  // namespace beaconloc
