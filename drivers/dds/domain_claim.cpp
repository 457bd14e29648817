#include "drivers/dds/domain_claim.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <stdexcept>
#include <string>

namespace eical::drivers::dds {

int claim_free_domain(int first, int last) {
  for (int id = first; id <= last; ++id) {
    const std::string path = "/tmp/eical-dds-domain-" + std::to_string(id) + ".lock";
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return id;  // fd stays open: the lock lives with the process
    ::close(fd);
  }
  throw std::runtime_error("dds: every domain id " + std::to_string(first) + ".." + std::to_string(last) +
                           " is claimed by another process on this host");
}

}  // namespace eical::drivers::dds
