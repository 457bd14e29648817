#pragma once
// A DDS domain id nobody else on this host is using right now, for tests and benchmarks
// that start their own daemon: parallel test processes on one domain hear each other's
// Results (a pid-derived id collided in CI). The claim is an exclusive flock on
// /tmp/eical-dds-domain-<id>.lock, held until the process exits (the kernel drops it even
// on a crash, so a stale file never blocks an id).
namespace eical::drivers::dds {

// Claims the first free id in [first, last] and returns it; every call claims another one
// (a test with two daemons needs two). Throws std::runtime_error when every id is taken.
int claim_free_domain(int first = 1, int last = 230);

}  // namespace eical::drivers::dds
