#pragma once
// The journal of `priormap scan --all` (OUT.partial): every finished scan's record, appended as it
// is done, so that a run stopped by Ctrl-C, SIGTERM or a crash goes on with --resume from the
// scans it had not finished. It is JSON Lines: a header with the run's fingerprint (the prior's
// text, the options and the log's bytes), then the records in the order they were finished.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace priormap::app {

class ScanJournal {
 public:
  // A new journal for `scans` scans of the run `fingerprint`, or, with `resume`, the journal
  // there of that run, whose records it keeps. Throws UserError when another run holds the
  // journal there (it is running), when a new one would replace a stopped run's, when --resume
  // finds none or one of another run, and for a damaged one (at file:line).
  ScanJournal(std::filesystem::path path, std::uint64_t fingerprint, std::size_t scans,
              bool resume);
  ~ScanJournal();
  ScanJournal(const ScanJournal&) = delete;
  ScanJournal& operator=(const ScanJournal&) = delete;

  // The record of scan k from an earlier session; empty when it has none.
  [[nodiscard]] const std::string& Record(std::size_t k) const { return records_[k]; }
  [[nodiscard]] std::size_t Restored() const { return restored_; }
  // Adds scan k's record (one line of JSON). Thread-safe; throws IoError when it cannot write.
  void Append(std::size_t k, const std::string& record);
  // The run is complete and its output written: the journal goes.
  void Remove();
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  void Restore(std::uint64_t fingerprint);

  std::filesystem::path path_;
  std::vector<std::string> records_;
  std::size_t restored_ = 0;
  std::FILE* file_ = nullptr;
  std::mutex mutex_;
  double last_sync_s_ = 0.0;
};

}  // namespace priormap::app
