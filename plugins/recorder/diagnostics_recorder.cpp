#include "diagnostics_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

namespace beaconloc {

using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::SampleInfo;

class DiagnosticsRecorder::Listener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  explicit Listener(DiagnosticsRecorder& owner) : owner_(owner) {}
  void on_data_available(DataReader* reader) override {
    msg::Diagnostics m;
    SampleInfo info;
    while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> lock(owner_.mutex_);
      owner_.latest_[m.participant()] = m;
    }
  }

 private:
  DiagnosticsRecorder& owner_;
};

DiagnosticsRecorder::DiagnosticsRecorder(const dds::DdsOptions& dds)
    : listener_(std::make_unique<Listener>(*this)),
      participant_(dds, "beaconloc.diagnostics_recorder"),
      reader_(participant_.reader<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic, listener_.get())) {}

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
    if (!d.message().empty()) out << " (" << d.message() << ')';
    out << '\n';
  }
}

}  // namespace beaconloc
