#include "scan_journal.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <optional>
#include <string_view>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>

#include "cli_support.hpp"

namespace priormap::app {
namespace {

constexpr const char* kFormat = "priormap.scan_journal";

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string Header(std::uint64_t fingerprint, std::size_t scans) {
  return nlohmann::json{{"format", kFormat},
                        {"version", 1},
                        {"fingerprint", fmt::format("{:016x}", fingerprint)},
                        {"scans", scans}}
      .dump();
}

// The refusal of a second run on the output of the run whose journal is at `path`.
UserError RunningElsewhere(const std::filesystem::path& path) {
  return UserError(fmt::format(
      "{}: another priormap scan --all is running on this output; wait for it to end or stop it "
      "(Ctrl-C keeps its scans for --resume)",
      path.string()));
}

// Whether another run holds the journal at `path` (it is running, not stopped). A journal that
// cannot be opened, or a file system without such locks, says nothing: false.
bool HeldByAnotherRun(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return held;
}

// The journal at `path` open for appending, locked (flock) against a second run on the same
// output: refused when another process holds it, or when `path` was replaced between the open
// and the lock (by another run starting there at the same moment).
std::FILE* OpenLocked(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_APPEND | O_CLOEXEC);
  if (fd < 0)
    throw IoError(
        fmt::format("{}: cannot open for appending: {}", path.string(), std::strerror(errno)));
  const auto refuse = [&] {
    ::close(fd);
    return RunningElsewhere(path);
  };
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) throw refuse();
    // A file system without such locks (some NFS set-ups): on, unlocked.
  }
  struct stat held {};
  struct stat named {};
  if (::fstat(fd, &held) != 0 || ::stat(path.c_str(), &named) != 0 || held.st_ino != named.st_ino ||
      held.st_dev != named.st_dev)
    throw refuse();
  std::FILE* file = ::fdopen(fd, "ab");
  if (file == nullptr) {
    ::close(fd);
    throw IoError(
        fmt::format("{}: cannot open for appending: {}", path.string(), std::strerror(errno)));
  }
  return file;
}

}  // namespace

ScanJournal::ScanJournal(std::filesystem::path path, std::uint64_t fingerprint, std::size_t scans,
                         bool resume)
    : path_(std::move(path)), records_(scans) {
  std::error_code ec;
  const bool exists = std::filesystem::exists(path_, ec);
  // A run going on there is refused as such, with or without --resume: its journal is no
  // stopped run's.
  if (exists && HeldByAnotherRun(path_)) throw RunningElsewhere(path_);
  if (!resume && exists)
    throw UserError(fmt::format(
        "{} holds a stopped scan --all of this output; continue it with the same command and "
        "--resume, or remove it to start anew",
        path_.string()));
  if (resume && !exists)
    throw UserError(fmt::format(
        "--resume: no {} (no stopped scan --all of this output to continue); run without "
        "--resume to start one",
        path_.string()));
  std::string text = Header(fingerprint, scans) + "\n";
  // The stopped run's journal, locked while it is read: a run still going on there is refused
  // rather than have its records replaced.
  std::FILE* stopped = resume ? OpenLocked(path_) : nullptr;
  try {
    if (resume) {
      Restore(fingerprint);
      for (const std::string& record : records_)
        if (!record.empty()) text += record + "\n";
    }
    // Rewritten whole: a crash may have left half a record at the end, which the next append
    // would run into.
    WriteTextFileAtomically(path_, text);
    file_ = OpenLocked(path_);
  } catch (...) {
    if (stopped != nullptr) std::fclose(stopped);
    throw;
  }
  if (stopped != nullptr) std::fclose(stopped);
  last_sync_s_ = Now();
}

ScanJournal::~ScanJournal() {
  if (file_ != nullptr) std::fclose(file_);
}

void ScanJournal::Restore(std::uint64_t fingerprint) {
  const Result<std::string> read = ReadFileText(path_);
  if (!read.ok()) {
    const Diagnostic& why = read.diagnostics().front();
    throw UserError(why.Location().empty() ? why.message : why.Location() + ": " + why.message);
  }
  const std::string& text = read.value();
  const std::string where = path_.string();
  std::size_t line_number = 0;
  std::size_t begin = 0;
  // A last line without its newline is a record a crash cut short: that scan is done again.
  for (std::size_t end; (end = text.find('\n', begin)) != std::string::npos; begin = end + 1) {
    ++line_number;
    const std::string_view line(text.data() + begin, end - begin);
    const auto located = [&](const std::string& what) {
      return UserError(fmt::format("{}:{}:1: {}", where, line_number, what));
    };
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (!j.is_object()) throw located("expected a JSON object on this line");
    if (line_number == 1) {
      // Members of another type, or counts that are not whole numbers, are no header of ours.
      const auto text_of = [&](const char* key) {
        const auto it = j.find(key);
        return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
      };
      const auto count_of = [&](const char* key) -> std::optional<std::uint64_t> {
        const auto it = j.find(key);
        if (it == j.end() || !it->is_number_unsigned()) return std::nullopt;
        return it->get<std::uint64_t>();
      };
      if (text_of("format") != kFormat || count_of("version") != 1u)
        throw located(fmt::format("expected the header of a {} (version 1)", kFormat));
      if (text_of("fingerprint") != fmt::format("{:016x}", fingerprint) ||
          count_of("scans") != static_cast<std::uint64_t>(records_.size()))
        throw UserError(fmt::format(
            "--resume: {} is a stopped run of another prior, log or options; give the same ones, "
            "or remove it to start anew",
            where));
      continue;
    }
    const auto index = j.find("scan_index");
    if (index == j.end() || !index->is_number_unsigned() ||
        index->get<std::size_t>() >= records_.size())
      throw located(
          fmt::format("expected a scan record with a scan_index below {}", records_.size()));
    std::string& record = records_[index->get<std::size_t>()];
    if (record.empty()) {
      record = line;
      ++restored_;
    }
  }
  if (line_number == 0)
    throw UserError(fmt::format("{}:1:1: expected the header of a {}", where, kFormat));
}

void ScanJournal::Append(std::size_t k, const std::string& record) {
  const std::lock_guard lock(mutex_);
  records_[k] = record;
  if (std::fputs(record.c_str(), file_) < 0 || std::fputc('\n', file_) == EOF ||
      std::fflush(file_) != 0)
    throw IoError(fmt::format("{}: cannot write: {}", path_.string(), std::strerror(errno)));
  // On disk every few seconds: what a power loss may take is a few seconds' scans.
  if (Now() - last_sync_s_ > 2.0) {
    if (::fsync(fileno(file_)) != 0)
      throw IoError(fmt::format("{}: cannot sync: {}", path_.string(), std::strerror(errno)));
    last_sync_s_ = Now();
  }
}

void ScanJournal::Remove() {
  // Unlinked while still locked: a run that opened it meanwhile finds it replaced and stops.
  std::filesystem::remove(path_);
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
}

}  // namespace priormap::app
