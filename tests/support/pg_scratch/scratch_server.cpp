#include "tests/support/pg_scratch/scratch_server.hpp"

#include <libpq-fe.h>

#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace eical::history::pg_scratch {
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

constexpr const char* kPrefix = "eical-pg-";

// Root runs the server as `nobody`: uid/gid to switch to, or -1 to stay.
struct RunAs {
  uid_t uid = static_cast<uid_t>(-1);
  gid_t gid = static_cast<gid_t>(-1);
};

RunAs run_as() {
  if (::geteuid() != 0) return {};
  const passwd* pw = ::getpwnam("nobody");
  if (!pw) throw std::runtime_error("pg_scratch: running as root and there is no user 'nobody' to run PostgreSQL as");
  return {pw->pw_uid, pw->pw_gid};
}

// In the child: drop to `who`, send the parent's death on as `death_signal` (0: none),
// output to `log`, exec. Only async-signal-safe calls after fork.
pid_t spawn(const std::vector<std::string>& argv, const std::string& log, RunAs who, int death_signal) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  if (who.uid != static_cast<uid_t>(-1)) {
    if (::setgroups(0, nullptr) != 0 || ::setgid(who.gid) != 0 || ::setuid(who.uid) != 0) ::_exit(126);
  }
  // After the credential change (which clears it): the server goes when its test goes.
  if (death_signal && (::prctl(PR_SET_PDEATHSIG, death_signal) != 0 || ::getppid() != parent)) ::_exit(125);
  ::setpgid(0, 0);  // not in the test's process group: a ^C goes to the test, which stops it
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (fd >= 0) ::dup2(fd, 1), ::dup2(fd, 2);
  ::execv(args[0], args.data());
  ::_exit(127);
}

int wait_for(pid_t pid, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  int st = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &st, WNOHANG);
    if (r == pid) return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    if (r < 0) return -1;
    if (std::chrono::steady_clock::now() > end) return -2;
    std::this_thread::sleep_for(20ms);
  }
}

std::string tail(const fs::path& file, std::size_t lines) {
  std::ifstream is(file);
  std::vector<std::string> all;
  for (std::string l; std::getline(is, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) out += "\n  " + all[i];
  return out;
}

bool alive(const fs::path& pidfile) {
  std::ifstream is(pidfile);
  long pid = 0;
  return (is >> pid) && pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH);
}

// Leftovers of a test that was killed: a directory whose owner (the process that started
// the server, owner.pid) is gone and whose server is gone too; one without an owner file
// when it is older than an hour. A live server's directory is never touched.
void remove_stale() {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (const auto& e : fs::directory_iterator(fs::temp_directory_path(), ec)) {
    if (!e.is_directory() || e.path().filename().string().rfind(kPrefix, 0) != 0) continue;
    if (alive(e.path() / "data" / "postmaster.pid")) continue;
    if (fs::exists(e.path() / "owner.pid") ? alive(e.path() / "owner.pid")
                                           : now - fs::last_write_time(e.path(), ec) < std::chrono::hours(1))
      continue;
    fs::remove_all(e.path(), ec);
  }
}

// Configure time found it (EICAL_PG_BINDIR); else the newest Debian server installed since.
std::string server_bindir() {
  std::string dir = EICAL_PG_BINDIR;
  if (!dir.empty() && fs::exists(fs::path(dir) / "postgres")) return dir;
  std::error_code ec;
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator("/usr/lib/postgresql", ec))
    if (fs::exists(e.path() / "bin" / "postgres")) found.push_back((e.path() / "bin").string());
  std::sort(found.begin(), found.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;  // "9" < "15" by length first
  });
  return found.empty() ? dir : found.back();
}

}  // namespace

ScratchServer::ScratchServer(ServerOptions options) : options_(options), bindir_(server_bindir()) {
  if (bindir_.empty() || !fs::exists(fs::path(bindir_) / "initdb") || !fs::exists(fs::path(bindir_) / "postgres"))
    throw std::runtime_error("pg_scratch: no PostgreSQL server programs (initdb, postgres) in '" + bindir_ +
                             "': install Debian's postgresql (scripts/deps.sh test) and re-run cmake");
  remove_stale();
  std::string tmpl = (fs::temp_directory_path() / (std::string(kPrefix) + "XXXXXX")).string();
  if (!::mkdtemp(tmpl.data()))
    throw std::runtime_error("pg_scratch: cannot create a temporary directory: " + std::string(std::strerror(errno)));
  dir_ = tmpl;
  std::ofstream(dir_ + "/owner.pid") << ::getpid() << "\n";
  const RunAs who = run_as();
  if (who.uid != static_cast<uid_t>(-1) && ::chown(dir_.c_str(), who.uid, who.gid) != 0) {
    const int err = errno;
    fs::remove_all(dir_);
    throw std::runtime_error("pg_scratch: cannot hand " + dir_ + " to user nobody: " + std::strerror(err));
  }
  ::chmod(dir_.c_str(), 0755);
  const std::string log = dir_ + "/initdb.log";
  const pid_t pid = spawn({bindir_ + "/initdb", "-D", dir_ + "/data", "-U", "eical", "-A", "trust", "-E", "UTF8",
                           "--locale=C", "--no-sync", "--no-instructions"},
                          log, who, SIGKILL);
  const int rc = wait_for(pid, 120s);
  if (rc != 0) {
    if (rc == -2) ::kill(pid, SIGKILL), (void)wait_for(pid, 5s);
    const std::string why = tail(log, 15);
    fs::remove_all(dir_);
    throw std::runtime_error("pg_scratch: initdb failed (exit " + std::to_string(rc) + "):" + why);
  }
  try {
    start();
  } catch (...) {
    fs::remove_all(dir_);
    throw;
  }
}

ScratchServer::~ScratchServer() {
  stop();
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

std::string ScratchServer::uri(const std::string& database) const {
  return "postgresql:///" + database + "?host=" + dir_ + "&port=5432&user=eical";
}

std::string ScratchServer::log_tail() const { return tail(fs::path(dir_) / "server.log", 20); }

void ScratchServer::start() {
  if (running()) return;
  // Unix socket in our directory only; SIGQUIT (immediate shutdown) when the test dies.
  pid_ = spawn({bindir_ + "/postgres", "-D", dir_ + "/data", "-k", dir_, "-p", "5432", "-c", "listen_addresses=", "-c",
                std::string("fsync=") + (options_.fsync ? "on" : "off")},
               dir_ + "/server.log", run_as(), SIGQUIT);
  const std::string conninfo = "host=" + dir_ + " port=5432 user=eical dbname=postgres connect_timeout=2";
  const auto end = std::chrono::steady_clock::now() + 60s;
  while (PQping(conninfo.c_str()) != PQPING_OK) {
    int st = 0;
    if (::waitpid(pid_, &st, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("pg_scratch: postgres exited at start:" + log_tail());
    }
    if (std::chrono::steady_clock::now() > end) {
      stop();
      throw std::runtime_error("pg_scratch: postgres did not accept connections within 60 s:" + log_tail());
    }
    std::this_thread::sleep_for(50ms);
  }
}

void ScratchServer::stop() {
  if (!running()) return;
  ::kill(pid_, SIGINT);  // fast shutdown: sessions are ended, no checkpoint wait for clients
  if (wait_for(pid_, 30s) == -2) {
    ::kill(pid_, SIGKILL);
    (void)wait_for(pid_, 5s);
  }
  pid_ = -1;
}

std::string ScratchServer::create_database(const std::string& name) {
  const std::string conninfo = "host=" + dir_ + " port=5432 user=eical dbname=postgres";
  PGconn* c = PQconnectdb(conninfo.c_str());
  std::string error;
  if (PQstatus(c) != CONNECTION_OK) {
    error = PQerrorMessage(c);
  } else {
    char* quoted = PQescapeIdentifier(c, name.c_str(), name.size());
    PGresult* r = PQexec(c, ("CREATE DATABASE " + std::string(quoted ? quoted : name.c_str())).c_str());
    PQfreemem(quoted);
    if (PQresultStatus(r) != PGRES_COMMAND_OK) error = PQresultErrorMessage(r);
    PQclear(r);
  }
  PQfinish(c);
  if (!error.empty()) throw std::runtime_error("pg_scratch: CREATE DATABASE " + name + ": " + error);
  return uri(name);
}

}  // namespace eical::history::pg_scratch
