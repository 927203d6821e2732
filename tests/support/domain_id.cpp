#include "domain_id.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <stdexcept>
#include <string>

namespace beaconloc::testing {

DomainLease::DomainLease() {
  // Start at a pid-dependent place so concurrent runs rarely contend, then probe.
  const int first = 1 + static_cast<int>(::getpid() % 200);
  for (int k = 0; k < 200; ++k) {
    const int id = 1 + (first - 1 + k) % 200;  // 1..200: clear of 0 and within 0..232
    const std::string path = "/tmp/beaconloc-domain-" + std::to_string(id) + ".lock";
    const int fd = ::open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      id_ = id;
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throw std::runtime_error("no free DDS domain id in 1..200");
}

DomainLease::~DomainLease() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace beaconloc::testing
