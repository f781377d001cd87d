#pragma once
/// Finding priors by name (for `specializes:` and the CLI) and compiling them.
///
/// A name resolves, in order, in: the directory of the file that asks (for `specializes:`), the
/// library's directories (`--prior-path`, then PRIORMAP_PRIOR_PATH), and the built-in library
/// (the files of priors/, compiled into priormap). Within one directory a name must be unique.

#include <filesystem>
#include <string>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/dsl/ast.hpp>
#include <priormap/dsl/prior.hpp>

namespace priormap::dsl {

/// One prior the library can resolve.
struct PriorListing {
  std::string name;
  std::string path;         ///< file, or "<builtin>/file.prior"
  std::string description;  ///< the file's first comment line
  bool builtin = false;
};

/// The files of priors/, compiled in: (file name, text).
[[nodiscard]] const std::vector<std::pair<std::string, std::string>>& BuiltinPriorTexts();

class PriorLibrary {
 public:
  explicit PriorLibrary(std::vector<std::filesystem::path> directories = {});

  /// The directories in PRIORMAP_PRIOR_PATH (':'-separated; empty entries ignored).
  [[nodiscard]] static std::vector<std::filesystem::path> EnvironmentPriorPath();
  /// The library searching `first` (a user's --prior-path), then PRIORMAP_PRIOR_PATH, then the
  /// built-ins: what the priormap app and the Python module use.
  [[nodiscard]] static PriorLibrary WithEnvironment(std::vector<std::filesystem::path> first);

  /// Every prior resolvable by name, directories first; a name shadowed by an earlier one is
  /// listed once.
  [[nodiscard]] std::vector<PriorListing> List() const;
  /// The first problem of each *.prior file in the directories that does not parse (List and
  /// name lookups pass over them).
  [[nodiscard]] std::vector<Diagnostic> Unparsable() const;

  /// Compiles the prior in file `file_or_name` when such a file exists, else the prior of that
  /// name.
  [[nodiscard]] Result<CompiledPrior> Load(const std::string& file_or_name) const;
  /// Compiles an already parsed prior, resolving its `specializes:` chain.
  [[nodiscard]] Result<CompiledPrior> Compile(const PriorFile& file) const;
  /// Compiles prior text; `path` names it and locates its parents.
  [[nodiscard]] Result<CompiledPrior> CompileText(std::string_view text,
                                                  const std::string& path) const;

 private:
  struct Candidate;
  /// The parsed prior called `name`, searching `first_directory` (if any) first.
  Result<PriorFile> Find(const std::string& name, const std::filesystem::path& first_directory,
                         const SourceLocation& requested_at) const;
  std::vector<std::filesystem::path> directories_;
};

}  // namespace priormap::dsl
