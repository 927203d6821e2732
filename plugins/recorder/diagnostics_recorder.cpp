#include "diagnostics_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include <fastdds/dds/core/LoanableSequence.hpp>

#include "beaconloc/dds/diagnostics_publisher.hpp"

namespace beaconloc {

using namespace eprosima::fastdds::dds;

const char* to_string(Liveness l) {
  switch (l) {
    case Liveness::kAlive:
      return "alive";
    case Liveness::kSilent:
      return "silent";
    case Liveness::kStopped:
      return "gone (stopped)";
    case Liveness::kGone:
      return "gone (no live writer)";
  }
  return "gone";
}

const char* to_string(msg::ParticipantStatus s) {
  switch (s) {
    case msg::PARTICIPANT_STATUS_OK:
      return "ok";
    case msg::PARTICIPANT_STATUS_DEGRADED:
      return "degraded";
    case msg::PARTICIPANT_STATUS_ERROR:
      return "error";
  }
  return "error";  // never: dds::CheckedType refuses a status the IDL does not define
}

Liveness liveness_of(InstanceStateKind state, std::chrono::nanoseconds age) {
  if (state == NOT_ALIVE_DISPOSED_INSTANCE_STATE) return Liveness::kStopped;
  if (state == NOT_ALIVE_NO_WRITERS_INSTANCE_STATE) return Liveness::kGone;
  return age > dds::kDiagnosticsSilentAfter ? Liveness::kSilent : Liveness::kAlive;
}

DiagnosticsRecorder::DiagnosticsRecorder(const dds::DdsOptions& dds)
    : participant_(dds, "beaconloc.diagnostics_recorder"),
      reader_(participant_.reader<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic, &listener_)) {}

void DiagnosticsRecorder::read(bool fresh) const {
  LoanableSequence<msg::Diagnostics> data;
  SampleInfoSeq infos;
  if (reader_->read(data, infos, LENGTH_UNLIMITED, fresh ? NOT_READ_SAMPLE_STATE : READ_SAMPLE_STATE,
                    ANY_VIEW_STATE, ANY_INSTANCE_STATE) != ReturnCode_t::RETCODE_OK) {
    return;  // none
  }
  const auto now = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (LoanableCollection::size_type i = 0; i < infos.length(); ++i) {
      const SampleInfo& info = infos[i];
      auto it = entries_.find(info.instance_handle);
      if (fresh && info.valid_data) {
        // (The listener and reports() may read two samples at once: the newer one stays.)
        if (it == entries_.end() || !(info.source_timestamp < it->second.sent)) {
          entries_[info.instance_handle] =
              Entry{data[i], info.source_timestamp, now, info.instance_state,
                    dds::participant_of_writer(dds::writer_id(info.publication_handle))};
        }
      } else if (it != entries_.end()) {
        it->second.state = info.instance_state;  // a participant never heard from is not shown
      }
    }
  }
  reader_->return_loan(data, infos);
}

std::map<std::string, ParticipantReport> DiagnosticsRecorder::reports() const {
  read(true);   // what the listener has not got to yet
  read(false);  // the instance states now
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<std::string, ParticipantReport> out;
  for (const auto& [handle, e] : entries_) {
    const auto age = now - e.heard;
    out[e.last.participant()] = {e.last, liveness_of(e.state, age), std::chrono::duration<double>(age).count(),
                                 e.participant_id};
  }
  return out;
}

std::map<std::string, msg::Diagnostics> DiagnosticsRecorder::latest() const {
  std::map<std::string, msg::Diagnostics> out;
  for (auto& [name, r] : reports()) out[name] = std::move(r.last);
  return out;
}

void print_report(const std::string& name, const ParticipantReport& r, std::ostream& out) {
  const auto& d = r.last;
  out << name << ": ";
  if (r.liveness == Liveness::kAlive) {
    out << to_string(d.status()) << ", ";
  } else {
    const long heard_s_ago = static_cast<long>(r.heard_s_ago);
    if (r.liveness == Liveness::kSilent) {
      out << "silent " << heard_s_ago << " s";
    } else {
      out << to_string(r.liveness) << ", last heard " << heard_s_ago << " s ago";
    }
    out << "; last report: ";
  }
  out << "accepted " << d.accepted();
  for (const auto& rc : d.rejected()) out << ", " << rc.reason() << ' ' << rc.count();
  out << ", deadline misses " << d.deadline_misses();
  if (d.writers_lost()) out << ", writers lost " << d.writers_lost();
  if (d.serving_conflicts()) out << ", serving conflicts " << d.serving_conflicts();
  if (!d.message().empty()) out << " (" << d.message() << ')';
  out << '\n';
}

void print_diagnostics(const std::map<std::string, ParticipantReport>& reports, std::ostream& out) {
  for (const auto& [name, r] : reports) print_report(name, r, out);
}

}  // namespace beaconloc
