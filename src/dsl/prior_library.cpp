#include <algorithm>
#include <cstdlib>
#include <set>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/dsl/parse.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "lexer.hpp"
#include "lower.hpp"

namespace priormap::dsl {
namespace fs = std::filesystem;
namespace {

constexpr const char* kBuiltinDirectory = "<builtin>";

std::string NameOf(const PriorFile& file) {
  const HeaderEntry* name = file.Header("name");
  return name ? name->value : "";
}

// The first sentence of the comment a prior file starts with (at most ~100 characters).
std::string Description(std::string_view text) {
  text = detail::WithoutByteOrderMark(text);
  std::string comment;
  // Lines end where the lexer's do: a file of CR endings is not one long comment line.
  for (std::size_t start = 0; start != std::string_view::npos;) {
    const detail::LineEnd line_end = detail::FindLineEnd(text, start);
    std::string_view line = text.substr(start, line_end.end - start);
    start = line_end.next;
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos) continue;
    if (line[first] != '#' && line[first] != '%') break;  // the comment block is over
    line.remove_prefix(first);
    line.remove_prefix(std::min(line.find_first_not_of("#% \t"), line.size()));
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    if (line.empty()) continue;
    if (!comment.empty()) comment += ' ';
    comment += line;
  }
  // The first ". " after a label such as "Fig. 2a:" ends the sentence.
  if (const std::size_t stop = comment.find(". ", 16); stop != std::string::npos)
    comment.resize(stop + 1);
  if (comment.size() > 100) comment = comment.substr(0, 97) + "...";
  return comment;
}

// The *.prior files of a directory that parse, sorted by file name; the first problem of each
// that does not parse (or cannot be read) in `broken`, when given.
std::vector<std::pair<PriorFile, std::string>> PriorsIn(const fs::path& directory,
                                                        std::vector<Diagnostic>* broken = nullptr) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(directory, ec)) {
    if (entry.path().extension() == ".prior" && entry.is_regular_file(ec))
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<std::pair<PriorFile, std::string>> priors;
  for (const fs::path& file : files) {
    Result<std::string> text = ReadFileText(file);
    if (!text) {
      if (broken) broken->push_back(text.diagnostics().front());
      continue;
    }
    Result<PriorFile> parsed = ParsePrior(text.value(), file.string());
    if (parsed) {
      priors.emplace_back(std::move(parsed).value(), Description(text.value()));
    } else if (broken) {
      broken->push_back(parsed.diagnostics().front());
    }
  }
  return priors;
}

// The prior asked for may be in a file that does not parse: the files passed over, for an
// error that could not find it.
std::string SkippedFiles(const std::vector<Diagnostic>& broken) {
  if (broken.empty()) return "";
  std::string out = "; these prior files were passed over as they do not parse:";
  for (const Diagnostic& d : broken) out += fmt::format("\n  {}: {}", d.Location(), d.message);
  return out;
}

std::vector<std::pair<PriorFile, std::string>> Builtins() {
  std::vector<std::pair<PriorFile, std::string>> priors;
  for (const auto& [file, text] : BuiltinPriorTexts()) {
    Result<PriorFile> parsed = ParsePrior(text, std::string(kBuiltinDirectory) + "/" + file);
    if (parsed) priors.emplace_back(std::move(parsed).value(), Description(text));
  }
  return priors;
}

}  // namespace

PriorLibrary::PriorLibrary(std::vector<fs::path> directories)
    : directories_(std::move(directories)) {}

std::vector<fs::path> PriorLibrary::EnvironmentPriorPath() {
  std::vector<fs::path> directories;
  const char* value = std::getenv("PRIORMAP_PRIOR_PATH");
  if (value == nullptr) return directories;
  std::string_view path(value);
  while (!path.empty()) {
    const std::size_t colon = path.find(':');
    const std::string_view entry = path.substr(0, colon);
    if (!entry.empty()) directories.emplace_back(std::string(entry));
    if (colon == std::string_view::npos) break;
    path.remove_prefix(colon + 1);
  }
  return directories;
}

PriorLibrary PriorLibrary::WithEnvironment(std::vector<fs::path> first) {
  for (fs::path& d : EnvironmentPriorPath()) first.push_back(std::move(d));
  return PriorLibrary(std::move(first));
}

std::vector<PriorListing> PriorLibrary::List() const {
  std::vector<PriorListing> listing;
  std::set<std::string> seen;
  const auto add = [&](std::vector<std::pair<PriorFile, std::string>> priors, bool builtin) {
    for (auto& [file, description] : priors) {
      const std::string name = NameOf(file);
      if (name.empty() || !seen.insert(name).second) continue;
      listing.push_back({name, file.path, description, builtin});
    }
  };
  for (const fs::path& directory : directories_) add(PriorsIn(directory), false);
  add(Builtins(), true);
  return listing;
}

std::vector<Diagnostic> PriorLibrary::Unparsable() const {
  std::vector<Diagnostic> broken;
  for (const fs::path& directory : directories_) (void)PriorsIn(directory, &broken);
  return broken;
}

Result<PriorFile> PriorLibrary::Find(const std::string& name, const fs::path& first_directory,
                                     const SourceLocation& requested_at) const {
  std::vector<fs::path> directories;
  std::error_code ec;
  if (!first_directory.empty() && fs::is_directory(first_directory, ec))
    directories.push_back(first_directory);
  for (const fs::path& d : directories_) directories.push_back(d);
  std::vector<std::string> searched;
  std::vector<Diagnostic> broken;
  for (const fs::path& directory : directories) {
    searched.push_back(directory.string());
    std::vector<PriorFile> matches;
    for (auto& [file, description] : PriorsIn(directory, &broken)) {
      if (NameOf(file) == name) matches.push_back(std::move(file));
    }
    if (matches.size() > 1) {
      return Diagnostic{requested_at.file_name(), requested_at.line, requested_at.col,
                        fmt::format("ambiguous prior name '{}': both {} and {} have it", name,
                                    matches[0].path, matches[1].path)};
    }
    if (matches.size() == 1) return std::move(matches[0]);
  }
  for (auto& [file, description] : Builtins()) {
    if (NameOf(file) == name) return std::move(file);
  }
  searched.push_back("the built-in library");
  return Diagnostic{requested_at.file_name(), requested_at.line, requested_at.col,
                    fmt::format("unknown prior '{}' (searched {}; see 'priormap prior list'){}",
                                name, fmt::join(searched, ", "), SkippedFiles(broken))};
}

Result<CompiledPrior> PriorLibrary::Compile(const PriorFile& file) const {
  detail::ResolvedPrior resolved;
  resolved.files.push_back(std::make_shared<const PriorFile>(file));
  std::vector<std::string> names = {NameOf(file)};
  for (;;) {
    const PriorFile& current = *resolved.files.back();
    const HeaderEntry* parent = current.Header("specializes");
    if (parent == nullptr) break;
    if (std::find(names.begin(), names.end(), parent->value) != names.end()) {
      names.push_back(parent->value);
      return Diagnostic{
          parent->value_loc.file_name(), parent->value_loc.line, parent->value_loc.col,
          fmt::format("inheritance cycle: '{}'", fmt::join(names, "' specializes '"))};
    }
    fs::path directory = fs::path(current.path).parent_path();
    // A file named without a directory is in the current one; text compiled from memory
    // ("<python>") has no directory of its own, and its parents come from the library alone.
    std::error_code ec;
    if (directory.empty() && fs::is_regular_file(current.path, ec)) directory = ".";
    Result<PriorFile> found = Find(
        parent->value, directory == kBuiltinDirectory ? fs::path() : directory, parent->value_loc);
    if (!found) return found.diagnostics();
    names.push_back(parent->value);
    resolved.files.push_back(std::make_shared<const PriorFile>(std::move(found).value()));
  }
  return detail::LowerAndCompile(resolved);
}

Result<CompiledPrior> PriorLibrary::CompileText(std::string_view text,
                                                const std::string& path) const {
  Result<PriorFile> parsed = ParsePrior(text, path);
  if (!parsed) return parsed.diagnostics();
  return Compile(parsed.value());
}

Result<CompiledPrior> PriorLibrary::Load(const std::string& file_or_name) const {
  std::error_code ec;
  if (fs::is_regular_file(file_or_name, ec)) {
    Result<PriorFile> parsed = ReadPriorFile(file_or_name);
    if (!parsed) return parsed.diagnostics();
    return Compile(parsed.value());
  }
  Result<PriorFile> found = Find(file_or_name, fs::path(), SourceLocation{});
  if (!found) {
    // A name given to two priors of one directory stays an error (not "no prior named").
    if (found.diagnostics().front().message.starts_with("ambiguous")) return found.diagnostics();
    // A convenience of the command line: a built-in or library file named by its stem
    // ("polygonal").
    for (const PriorListing& listing : List()) {
      if (fs::path(listing.path).stem() == file_or_name) return Load(listing.name);
    }
    if (fs::is_directory(file_or_name, ec))
      return Diagnostic{file_or_name, 0, 0,
                        "a directory, not a prior file or name (a directory of priors is searched "
                        "with --prior-path)"};
    return Diagnostic{"", 0, 0,
                      fmt::format("no prior file or prior named '{}' (see 'priormap prior list'){}",
                                  file_or_name, SkippedFiles(Unparsable()))};
  }
  return Compile(found.value());
}

}  // namespace priormap::dsl
