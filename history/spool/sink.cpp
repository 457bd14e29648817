#include "history/spool/sink.hpp"

#include "history/sql/pg_connection.hpp"
#include "history/store/store.hpp"

#include <cstdio>
#include <memory>

namespace eical::history {

namespace {
constexpr std::size_t kBatch = 100;  // results per transaction when a backlog drains

std::string seconds(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", s);
  return b;
}
}  // namespace

Sink::Sink(SinkConfig config, Log log) : config_(std::move(config)), log_(std::move(log)), spool_(config_.spool_dir) {
  waiting_ = spool_.waiting().size();
  if (waiting_ > 0)
    log_(Level::info, "history: " + std::to_string(waiting_) + " results from before wait in " + spool_.dir().string());
  thread_ = std::thread([this] { writer(); });
}

Sink::~Sink() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
  if (!memory_.empty())
    log_(Level::error, "history: " + std::to_string(memory_.size()) +
                           " results could neither be spooled nor stored; their run directories keep result.json "
                           "(eical history add RUN)");
}

void Sink::submit(const Record& r) {
  std::string error;
  {
    // The file and its count appear together: a writer that finds the file on disk and
    // fails to store it then reports it among those waiting, not "0 results wait".
    std::lock_guard lk(mu_);
    try {
      spool_.put(r);
    } catch (const std::exception& e) {
      error = e.what();
      memory_.emplace_back(std::filesystem::path(), r);
    }
    ++waiting_;
    wake_ = true;
  }
  if (!error.empty())
    log_(Level::error,
         "history: cannot spool result " + r.run_id + " (" + error + "); held in memory until the store takes it");
  cv_.notify_all();
}

std::string Sink::problem() const {
  std::lock_guard lk(mu_);
  return problem_;
}

std::size_t Sink::waiting() const {
  std::lock_guard lk(mu_);
  return waiting_;
}

Sink::Counts Sink::counts() const {
  std::lock_guard lk(mu_);
  return counts_;
}

bool Sink::wait_drained(std::chrono::milliseconds timeout) {
  std::unique_lock lk(mu_);
  return drained_.wait_for(lk, timeout, [&] { return waiting_ == 0; });
}

void Sink::retry_now() {
  {
    std::lock_guard lk(mu_);
    wake_ = true;
  }
  cv_.notify_all();
}

void Sink::set_problem(const std::string& p) {
  std::string changed;
  std::size_t waiting = 0;
  {
    std::lock_guard lk(mu_);
    if (p == problem_) return;
    const bool recovered = p.empty();
    problem_ = p;
    waiting = waiting_;
    changed = recovered ? "history: store " + sql::redact_uri(config_.location) + " is taking results again"
                        : "history: " + p + "; " + std::to_string(waiting) + " results wait in " +
                              spool_.dir().string() + ", tried again every " + seconds(config_.retry_s) + " s";
  }
  log_(p.empty() ? Level::info : Level::error, changed);
}

bool Sink::flush() {
  for (;;) {
    // The next batch: spooled files first (oldest first), then what only memory holds.
    std::vector<std::filesystem::path> files = spool_.waiting();
    if (files.size() > kBatch) files.resize(kBatch);
    std::vector<Record> batch;
    std::vector<std::filesystem::path> used;
    for (const auto& f : files) {
      try {
        batch.push_back(Spool::read(f));
        used.push_back(f);
      } catch (const std::exception& e) {
        const auto to = spool_.set_aside(f);
        log_(Level::error, "history: " + std::string(e.what()) + "; set aside as " + to.string());
        std::lock_guard lk(mu_);
        ++counts_.set_aside;
        if (waiting_) --waiting_;
      }
    }
    std::size_t from_memory = 0;
    {
      std::lock_guard lk(mu_);
      for (; from_memory < memory_.size() && batch.size() < kBatch; ++from_memory)
        batch.push_back(memory_[from_memory].second);
    }
    if (batch.empty()) {
      std::lock_guard lk(mu_);
      waiting_ = spool_.waiting().size() + memory_.size();
      if (waiting_ == 0) drained_.notify_all();
      return waiting_ == 0;
    }
    std::vector<AddOutcome> outcomes;
    try {
      if (!store_) store_ = Store::open(config_.location, {.create = config_.create});
      outcomes = store_->add_many(batch);
    } catch (const std::exception& e) {
      store_.reset();  // a new connection next time (the server may be back, the lock gone)
      set_problem(e.what());
      return false;
    }
    for (const auto& f : used) spool_.remove(f);
    {
      std::lock_guard lk(mu_);
      memory_.erase(memory_.begin(), memory_.begin() + static_cast<std::ptrdiff_t>(from_memory));
      for (const auto o : outcomes) ++(o == AddOutcome::added ? counts_.stored : counts_.duplicates);
      waiting_ = waiting_ > batch.size() ? waiting_ - batch.size() : 0;
    }
    set_problem("");
  }
}

void Sink::writer() {
  std::unique_lock lk(mu_);
  for (;;) {
    if (!wake_ && !stop_) {
      cv_.wait(lk, [&] { return stop_ || wake_; });
      continue;
    }
    // At the stop, one last attempt unless the store is known to be away (what it does not
    // take stays spooled for the next start; the stop is not held up by a dead server).
    const bool last = stop_;
    if (last && !problem_.empty()) return;
    wake_ = false;
    lk.unlock();
    const bool done = flush();
    lk.lock();
    if (last) return;
    if (!done) {
      // Wait retry_s (or a new result / retry_now) before the next attempt.
      cv_.wait_for(lk, std::chrono::duration<double>(config_.retry_s), [&] { return stop_ || wake_; });
      wake_ = true;
    }
  }
}

}  // namespace eical::history
