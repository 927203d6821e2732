#pragma once
// Counts of accepted inputs and of rejected ones by reason, for a participant's Diagnostics.
#include <cstdint>
#include <map>
#include <string>

#include "beaconloc/core/rejection.hpp"

namespace beaconloc {

class RejectionCounter {
 public:
  void accept() { ++accepted_; }
  void reject(const std::string& reason) { ++rejected_[reason]; }
  // Counted under prefix + the reason's stable name ("range.gated_nis").
  void reject(const std::string& prefix, Rejection reason) { ++rejected_[prefix + to_string(reason)]; }
  void reject(const std::string& reason, std::uint64_t count) {
    if (count) rejected_[reason] += count;
  }
  std::uint64_t accepted() const { return accepted_; }
  std::uint64_t rejected(const std::string& reason) const {
    auto it = rejected_.find(reason);
    return it == rejected_.end() ? 0 : it->second;
  }
  std::uint64_t rejected_total() const {
    std::uint64_t n = 0;
    for (const auto& [reason, count] : rejected_) n += count;
    return n;
  }
  const std::map<std::string, std::uint64_t>& rejected_by_reason() const { return rejected_; }
  // Adds another counter's rejections under prefix + reason (its accepted count is not added).
  void add_rejections(const RejectionCounter& other, const std::string& prefix) {
    for (const auto& [reason, count] : other.rejected_) rejected_[prefix + reason] += count;
  }

 private:
  std::uint64_t accepted_ = 0;
  std::map<std::string, std::uint64_t> rejected_;
};

}  // namespace beaconloc
