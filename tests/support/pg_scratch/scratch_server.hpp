#pragma once
// A PostgreSQL server of its own for tests and benchmarks: initdb and postgres in a fresh
// temporary directory, listening only on a Unix socket there (no TCP port, nothing shared
// with another server or test on the host), stopped and removed by the destructor. The
// server dies with the process that started it (PR_SET_PDEATHSIG), so a crashed or killed
// test leaves no server behind; directories such leftovers leave are removed at the next
// start.
//
// initdb and postgres refuse to run as root: started by root, the server runs as the
// unprivileged user `nobody` (privileges dropped in the child before exec; the temporary
// directory is handed to that user). Otherwise it runs as the calling user.
#include <sys/types.h>
#include <string>

namespace eical::history::pg_scratch {

struct ServerOptions {
  bool fsync = true;  // false: faster for functional tests (durability is not what they test)
};

class ScratchServer {
 public:
  // Throws std::runtime_error with the cause (no PostgreSQL installed, initdb failed, the
  // server did not come up: the end of its log).
  explicit ScratchServer(ServerOptions options = {});
  ~ScratchServer();
  ScratchServer(const ScratchServer&) = delete;
  ScratchServer& operator=(const ScratchServer&) = delete;

  // libpq URI of a database on this server (the superuser `eical`, trust over the socket).
  [[nodiscard]] std::string uri(const std::string& database = "postgres") const;
  // Creates a database and returns its URI.
  std::string create_database(const std::string& name);

  void stop();   // fast shutdown; the data stays (start() again: "the database went away")
  void start();  // (again) on the same data; waits until it accepts connections
  [[nodiscard]] bool running() const { return pid_ > 0; }
  [[nodiscard]] const std::string& dir() const { return dir_; }
  [[nodiscard]] std::string log_tail() const;

 private:
  ServerOptions options_;
  std::string dir_, bindir_;
  pid_t pid_ = -1;
};

}  // namespace eical::history::pg_scratch
