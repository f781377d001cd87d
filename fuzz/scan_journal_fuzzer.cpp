// libFuzzer harness for the journal of `priormap scan --all` (ScanJournal, apps/priormap: the
// OUT.partial that `scan --all --resume` continues): the input is the journal, opened with
// --resume for a run of kScans scans whose fingerprint is kFingerprint. Besides crashes and
// sanitizer reports it checks that
//  - a refused journal is a UserError that names it (what main prints), never another exception;
//  - a journal accepted holds, for every scan k, no record or a JSON object whose scan_index is
//    k, and Restored() counts the records;
//  - against a model of the format: a journal accepted has the run's fingerprint and scan count,
//    no damaged line, and the records of its complete lines (a last line without its newline is
//    dropped; the first record of a scan wins); a journal the model finds well-formed (the
//    header's values of their JSON types) is accepted;
//  - the journal rewritten on open (header, then the records in scan order) opens again to the
//    same records and is rewritten to the same bytes; a record appended is there on the next
//    open; the rewritten journal is refused for another fingerprint or scan count, and a new run
//    over it is refused; Remove() deletes it.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "fuzz_check.hpp"
#include "fuzz_scratch.hpp"
#include "scan_journal.hpp"

using priormap::app::ScanJournal;
using priormap::fuzz::Check;
namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kFingerprint = 0x0123456789abcdefULL;
constexpr std::size_t kScans = 8;

// The journal at `path` opened for the run (fingerprint, scans), or nullptr when refused as it
// should be: a UserError naming the journal.
std::unique_ptr<ScanJournal> Open(const fs::path& path, std::uint64_t fingerprint,
                                  std::size_t scans, bool resume) {
  try {
    return std::make_unique<ScanJournal>(path, fingerprint, scans, resume);
  } catch (const priormap::app::UserError& e) {
    const std::string_view message = e.what();
    Check(message.find(path.string()) != std::string_view::npos,
          "a refused journal is a UserError that names it", message);
    return nullptr;
  } catch (const std::exception& e) {
    Check(false, "ScanJournal throws UserError only", e.what());
  }
  return nullptr;
}

// What the journal `text` holds by docs/formats.md, for the run (kFingerprint, kScans).
struct Model {
  bool run = false;          // a header of this run's fingerprint and scan count
  bool well_formed = false;  // a header of its JSON types, every record line a record below kScans
  bool damaged_record = false;  // a complete line after the header that is no record below kScans
  std::vector<std::string> records = std::vector<std::string>(kScans);
};

Model ModelOf(std::string_view text) {
  Model m;
  std::vector<std::string_view> lines;
  for (std::size_t begin = 0, end; (end = text.find('\n', begin)) != std::string_view::npos;
       begin = end + 1)
    lines.push_back(text.substr(begin, end - begin));
  if (lines.empty()) return m;
  const nlohmann::json header = nlohmann::json::parse(lines[0], nullptr, false);
  const auto field = [&](const char* key) {
    return header.is_object() && header.contains(key) ? header[key] : nlohmann::json();
  };
  const nlohmann::json fingerprint = field("fingerprint");
  const nlohmann::json scans = field("scans");
  // The scan count a whole number, as the reader takes it (8.0 or 8.9 is no count).
  m.run = fingerprint.is_string() && fingerprint == fmt::format("{:016x}", kFingerprint) &&
          scans.is_number_unsigned() && scans.get<std::uint64_t>() == kScans;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const nlohmann::json record = nlohmann::json::parse(lines[i], nullptr, false);
    const auto index = record.is_object() ? record.find("scan_index") : record.end();
    if (!record.is_object() || index == record.end() || !index->is_number_unsigned() ||
        index->get<std::uint64_t>() >= kScans) {
      m.damaged_record = true;
      continue;
    }
    std::string& slot = m.records[index->get<std::size_t>()];
    if (slot.empty()) slot = lines[i];
  }
  const nlohmann::json format = field("format");
  const nlohmann::json version = field("version");
  m.well_formed = format == "priormap.scan_journal" && version.is_number_integer() &&
                  version == 1 && m.run && scans.is_number_unsigned() && !m.damaged_record;
  return m;
}

std::vector<std::string> Records(const ScanJournal& journal) {
  std::vector<std::string> records;
  for (std::size_t k = 0; k < kScans; ++k) records.push_back(journal.Record(k));
  return records;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const priormap::fuzz::ScratchDirectory& scratch = priormap::fuzz::Scratch();
  const fs::path path = scratch.Write("scans.jsonl.partial", text);
  const Model model = ModelOf(text);
  std::unique_ptr<ScanJournal> journal = Open(path, kFingerprint, kScans, true);
  if (!journal) {
    Check(!model.well_formed, "a well-formed journal of the run is accepted");
    Check(priormap::fuzz::ReadBytes(path) == text, "a refused journal is left as it is");
    return 0;
  }
  Check(model.run, "a journal accepted has the run's fingerprint and scan count");
  Check(!model.damaged_record, "a journal accepted has no damaged line");
  const std::vector<std::string> records = Records(*journal);
  Check(records == model.records,
        "a journal accepted holds the records of its complete lines, the first of each scan");
  std::size_t restored = 0;
  std::string expected = nlohmann::json{{"format", "priormap.scan_journal"},
                                        {"version", 1},
                                        {"fingerprint", fmt::format("{:016x}", kFingerprint)},
                                        {"scans", kScans}}
                             .dump() +
                         "\n";
  for (std::size_t k = 0; k < kScans; ++k) {
    if (records[k].empty()) continue;
    ++restored;
    expected += records[k] + "\n";
    Check(records[k].find('\n') == std::string::npos, "a record is one line", records[k]);
    const nlohmann::json record = nlohmann::json::parse(records[k], nullptr, false);
    Check(record.is_object(), "a record restored is a JSON object", records[k]);
    const auto index = record.find("scan_index");
    Check(index != record.end() && index->is_number_unsigned() && index->get<std::size_t>() == k,
          "the record of scan k has scan_index k", records[k]);
  }
  Check(journal->Restored() == restored, "Restored() counts the records restored");
  journal.reset();
  const std::string rewritten = priormap::fuzz::ReadBytes(path);
  Check(rewritten == expected, "the journal is rewritten as its header and records in scan order",
        rewritten);

  // Opened again: the same records, the same bytes.
  journal = Open(path, kFingerprint, kScans, true);
  Check(journal != nullptr, "a rewritten journal opens again", rewritten);
  Check(Records(*journal) == records && journal->Restored() == restored,
        "a rewritten journal restores the same records", rewritten);
  // A record appended for a scan that has none is there on the next open.
  std::size_t missing = 0;
  while (missing < kScans && !records[missing].empty()) ++missing;
  const std::string appended = fmt::format(R"({{"scan_index":{},"fuzz":true}})", missing);
  if (missing < kScans) journal->Append(missing, appended);
  journal.reset();
  Check(priormap::fuzz::ReadBytes(path) ==
            (missing < kScans ? rewritten + appended + "\n" : rewritten),
        "an append adds one line");
  journal = Open(path, kFingerprint, kScans, true);
  Check(journal != nullptr, "a journal appended to opens again");
  for (std::size_t k = 0; k < kScans; ++k)
    Check(journal->Record(k) == (k == missing ? appended : records[k]),
          "the appended record is restored with the others");
  Check(journal->Restored() == restored + (missing < kScans ? 1 : 0), "Restored() counts it");
  journal.reset();
  const std::string before = priormap::fuzz::ReadBytes(path);

  // Another run's journal, and a new run over one: refused, the journal left as it is.
  Check(Open(path, kFingerprint ^ 1, kScans, true) == nullptr,
        "a journal of another fingerprint is refused");
  Check(Open(path, kFingerprint, kScans + 1, true) == nullptr,
        "a journal of another scan count is refused");
  Check(Open(path, kFingerprint, kScans, false) == nullptr, "a new run over a journal is refused");
  Check(priormap::fuzz::ReadBytes(path) == before, "a refused journal is left as it is");

  journal = Open(path, kFingerprint, kScans, true);
  Check(journal != nullptr, "the journal opens once more");
  journal->Remove();
  Check(!fs::exists(path), "Remove() deletes the journal");
  return 0;
}
