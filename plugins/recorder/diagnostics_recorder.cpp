#include "diagnostics_recorder.hpp"

#include <beaconlocPubSubTypes.h>

namespace beaconloc {

DiagnosticsRecorder::DiagnosticsRecorder(const dds::DdsOptions& dds)
    : participant_(dds, "beaconloc.diagnostics_recorder") {
  participant_.subscribe<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic,
                                                     [this](const msg::Diagnostics& m) {
                                                       std::lock_guard<std::mutex> lock(mutex_);
                                                       latest_[m.participant()] = m;
                                                     });
}

DiagnosticsRecorder::~DiagnosticsRecorder() { participant_.close(); }

std::map<std::string, msg::Diagnostics> DiagnosticsRecorder::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

void print_diagnostics(const std::map<std::string, msg::Diagnostics>& latest, std::ostream& out) {
  static const char* kStatus[] = {"ok", "degraded", "error"};
  for (const auto& [name, d] : latest) {
    out << name << ": " << kStatus[static_cast<int>(d.status()) % 3] << ", accepted " << d.accepted();
    for (const auto& r : d.rejected()) out << ", " << r.reason() << ' ' << r.count();
    out << ", deadline misses " << d.deadline_misses();
    if (d.writers_lost()) out << ", writers lost " << d.writers_lost();
    if (!d.message().empty()) out << " (" << d.message() << ')';
    out << '\n';
  }
}

}  // namespace beaconloc
