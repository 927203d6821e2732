#pragma once
// A DDS domain id no other test run on this machine holds: an exclusive lock on
// /tmp/beaconloc-domain-<id>.lock, held until the Lease is destroyed. Domain 0 is never used.
namespace beaconloc::testing {

class DomainLease {
 public:
  DomainLease();
  ~DomainLease();
  DomainLease(const DomainLease&) = delete;
  DomainLease& operator=(const DomainLease&) = delete;
  int id() const { return id_; }

 private:
  int id_ = -1;
  int fd_ = -1;
};

}  // namespace beaconloc::testing
