#pragma once
// The spool: results waiting for the history store, one file each in a directory, written
// durably (temporary file, fsync, rename, fsync of the directory) so a result handed to
// the spool survives a crash or a power cut. Names sort in the order results arrived.
//   <dir>/<20-digit ns>-<pid>-<n>.json   {"format": "eical-history-spool/1", "record": {...}}
//   <dir>/bad/                           files that could not be read back (kept, never deleted)
#include "history/record/record.hpp"

#include <filesystem>
#include <vector>

namespace eical::history {

class Spool {
 public:
  explicit Spool(std::filesystem::path dir) : dir_(std::move(dir)) {}

  // Writes one record; returns its file. Throws std::runtime_error naming the path and
  // the system's reason (directory missing and not creatable, disk full, read-only).
  std::filesystem::path put(const Record& r);
  // The waiting files, oldest first.
  [[nodiscard]] std::vector<std::filesystem::path> waiting() const;
  // Reads one back; throws std::runtime_error naming the file when it is not a record.
  static Record read(const std::filesystem::path& file);
  void remove(const std::filesystem::path& file) const;
  // Moves an unreadable file to <dir>/bad/ (returns where it went).
  std::filesystem::path set_aside(const std::filesystem::path& file) const;

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

}  // namespace eical::history
