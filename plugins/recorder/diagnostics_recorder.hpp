#pragma once
// Keeps the latest Diagnostics of every participant on the bus and whether the participant is
// still there (monitor, run, tests). Liveness comes from the DDS instance state of the
// participant's Diagnostics (keyed by its name): NOT_ALIVE_DISPOSED when it stopped (its
// DiagnosticsPublisher disposes on stop), NOT_ALIVE_NO_WRITERS when its writer vanished (a
// killed process, once its DDS lease expires, or a lost liveliness); and from the age of its
// newest report: silent past dds::kDiagnosticsSilentAfter (hung, or killed but not yet expired).
#include <beaconloc.h>

#include <chrono>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc {

enum class Liveness {
  kAlive,    // reporting
  kSilent,   // alive to DDS, but no report for dds::kDiagnosticsSilentAfter
  kStopped,  // it disposed its instance: stopped cleanly
  kGone,     // no live writer: it exited without a word, was killed, or lost its liveliness
};
const char* to_string(Liveness l);
const char* to_string(msg::ParticipantStatus s);

struct ParticipantReport {
  msg::Diagnostics last;  // its newest report
  Liveness liveness = Liveness::kAlive;
  double heard_s_ago = 0.0;  // since that report arrived
  // Its participant's id (dds::participant_of_writer of the report's writer): the other
  // writers of that participant (a localizer's poses) begin with it.
  std::string participant_id;
};

// What the instance state and the age of the newest report say (age in steady-clock time).
Liveness liveness_of(eprosima::fastdds::dds::InstanceStateKind state, std::chrono::nanoseconds age);

class DiagnosticsRecorder {
 public:
  explicit DiagnosticsRecorder(const dds::DdsOptions& dds);
  // By participant name, with each one's liveness now.
  std::map<std::string, ParticipantReport> reports() const;
  // The newest report of each participant that ever reported, gone or not (its counts).
  std::map<std::string, msg::Diagnostics> latest() const;

 private:
  struct Entry {
    msg::Diagnostics last;
    eprosima::fastrtps::rtps::Time_t sent;  // its source timestamp
    std::chrono::steady_clock::time_point heard;
    eprosima::fastdds::dds::InstanceStateKind state;
    std::string participant_id;
  };
  class Listener : public eprosima::fastdds::dds::DataReaderListener {
   public:
    explicit Listener(DiagnosticsRecorder& r) : recorder_(r) {}
    void on_data_available(eprosima::fastdds::dds::DataReader*) override { recorder_.read(true); }

   private:
    DiagnosticsRecorder& recorder_;
  };
  // The reader keeps each participant's newest sample (keep_last 1): read, never taken, so that
  // its instance state can be read again. fresh: the samples not read yet (their reports), else
  // those already read (only their instance state, which changes without a sample).
  void read(bool fresh) const;

  mutable std::mutex mutex_;
  mutable std::map<eprosima::fastdds::dds::InstanceHandle_t, Entry> entries_;  // by instance
  Listener listener_{*this};
  dds::Participant participant_;
  dds::Reader reader_;  // last: stops before the listener and the entries go
};

// One line per participant: its liveness and status, accepted, rejected by reason, deadline
// misses. A participant gone or silent shows as such with its last counts, never its last status.
void print_diagnostics(const std::map<std::string, ParticipantReport>& reports, std::ostream& out);
void print_report(const std::string& name, const ParticipantReport& report, std::ostream& out);

}  // namespace beaconloc
