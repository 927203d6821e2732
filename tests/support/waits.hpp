#pragma once
// Waiting for an event in a multi-process test, never for a fixed time: until a condition holds
// or a timeout (scaled() under the sanitizers) passes.
#include <chrono>
#include <functional>
#include <string>
#include <thread>

#include "diagnostics_recorder.hpp"
#include "process.hpp"

namespace beaconloc::testing {

// Whether pred() came to hold within the timeout (polled every 20 ms).
template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + scaled(timeout);
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// The newest Diagnostics of the first participant whose name starts with `prefix` that
// satisfies `ready`, or the last such Diagnostics seen when the timeout passes (empty if none).
inline msg::Diagnostics wait_for_diagnostics(const DiagnosticsRecorder& recorder, const std::string& prefix,
                                             const std::function<bool(const msg::Diagnostics&)>& ready,
                                             std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  msg::Diagnostics last;
  eventually(
      [&] {
        for (const auto& [name, d] : recorder.latest()) {
          if (name.rfind(prefix, 0) != 0) continue;
          last = d;
          if (ready(d)) return true;
        }
        return false;
      },
      timeout);
  return last;
}

}  // namespace beaconloc::testing
