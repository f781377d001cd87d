// Finding priors: names resolved for `specializes:` and for the command line, in the file's own
// directory, then the library's directories (--prior-path, PRIORMAP_PRIOR_PATH), then the
// built-in library; listing them; and the built-in library itself.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/dsl/parse.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::dsl {
namespace {

namespace fs = std::filesystem;
using priormap::testing::DiagnosticAt;
using priormap::testing::ReadAll;
using priormap::testing::TempDir;
using priormap::testing::WriteAll;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A prior called `name` whose same_region block holds one recognisable energy `marker`, so
// that a test can tell which of several same-named files was used.
std::string Marked(const std::string& name, int marker) {
  return "# " + name + " number " + std::to_string(marker) + ".\nname: " + name +
         "\norder: 2\npriorlet same_region:\n  model_likelihood " + std::to_string(marker) +
         " * alpha_1\n";
}

// The marker of the prior's same_region energy (its derivative by alpha_1).
std::string MarkerOf(const CompiledPrior& prior) {
  const CompiledBlock* block = prior.block(BlockKind::kSameRegion);
  if (!block || block->num_terms() == 0) return "none";
  return block->DerivativeExpression(block->num_terms() - 1, 2);
}

std::string Child(const std::string& parent) {
  return "name: Child\nspecializes: " + parent +
         "\npriorlet different_region:\n  alpha_1 == alpha_2\n";
}

// Sets (or unsets) an environment variable for the lifetime of the object, then restores it.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnvironment() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// Changes the working directory for the lifetime of the object.
class ScopedWorkingDirectory {
 public:
  explicit ScopedWorkingDirectory(const fs::path& dir) : old_(fs::current_path()) {
    fs::current_path(dir);
  }
  ~ScopedWorkingDirectory() { fs::current_path(old_); }
  ScopedWorkingDirectory(const ScopedWorkingDirectory&) = delete;
  ScopedWorkingDirectory& operator=(const ScopedWorkingDirectory&) = delete;

 private:
  fs::path old_;
};

// --- specializes -------------------------------------------------------------------------------

TEST(PriorLibrarySpecializes, BuiltinParentIsFoundByName) {
  TempDir dir;
  const Result<CompiledPrior> prior =
      PriorLibrary().CompileText(Child("Polygonal prior"), (dir / "c.prior").string());
  ASSERT_TRUE(prior.ok()) << prior.error();
  ASSERT_EQ(prior.value().chain().size(), 2u);
  EXPECT_EQ(prior.value().chain()[1].name, "Polygonal prior");
  EXPECT_EQ(prior.value().chain()[1].path, "<builtin>/polygonal.prior");
  EXPECT_EQ(prior.value().block(BlockKind::kSameRegion)->num_terms(),
            2);  // the polygonal constraints
  EXPECT_EQ(prior.value().max_curvature(), 0.0);
}

TEST(PriorLibrarySpecializes, FileInTheSameDirectoryShadowsABuiltinOfTheSameName) {
  TempDir dir;
  WriteAll(dir / "my-polygonal.prior", Marked("Polygonal prior", 7));
  const Result<CompiledPrior> prior =
      PriorLibrary().CompileText(Child("Polygonal prior"), (dir / "c.prior").string());
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(prior.value().chain()[1].path, (dir / "my-polygonal.prior").string());
  EXPECT_EQ(MarkerOf(prior.value()), "7");
}

TEST(PriorLibrarySpecializes, OwnDirectoryComesBeforeTheLibraryDirectories) {
  TempDir own, library;
  WriteAll(own / "base.prior", Marked("Base", 1));
  WriteAll(library / "base.prior", Marked("Base", 2));
  const Result<CompiledPrior> prior =
      PriorLibrary({library.path()}).CompileText(Child("Base"), (own / "c.prior").string());
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(MarkerOf(prior.value()), "1");
}

TEST(PriorLibrarySpecializes, LibraryDirectoriesAreSearchedInOrderBeforeTheBuiltins) {
  TempDir own, first, second;
  WriteAll(second / "base.prior", Marked("Base", 2));
  WriteAll(second / "polygonal.prior", Marked("Polygonal prior", 3));
  const PriorLibrary library({first.path(), second.path()});
  const Result<CompiledPrior> base = library.CompileText(Child("Base"), (own / "c.prior").string());
  ASSERT_TRUE(base.ok()) << base.error();
  EXPECT_EQ(MarkerOf(base.value()), "2");
  const Result<CompiledPrior> polygonal =
      library.CompileText(Child("Polygonal prior"), (own / "c.prior").string());
  ASSERT_TRUE(polygonal.ok()) << polygonal.error();
  EXPECT_EQ(MarkerOf(polygonal.value()), "3");

  WriteAll(first / "base.prior", Marked("Base", 1));
  const Result<CompiledPrior> shadowed =
      library.CompileText(Child("Base"), (own / "c.prior").string());
  ASSERT_TRUE(shadowed.ok()) << shadowed.error();
  EXPECT_EQ(MarkerOf(shadowed.value()), "1");
}

TEST(PriorLibrarySpecializes, ParentOfARelativePathIsFoundInTheWorkingDirectory) {
  TempDir dir;
  WriteAll(dir / "base.prior", Marked("Base", 4));
  WriteAll(dir / "child.prior", Child("Base"));
  const ScopedWorkingDirectory cwd(dir.path());
  const Result<CompiledPrior> prior = PriorLibrary().Load("child.prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(MarkerOf(prior.value()), "4");
}

TEST(PriorLibrarySpecializes, TwoFilesWithTheNameInOneDirectoryAreAmbiguous) {
  TempDir dir;
  WriteAll(dir / "a.prior", Marked("Base", 1));
  WriteAll(dir / "b.prior", Marked("Base", 2));
  const std::string child = (dir / "c.prior").string();
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(Child("Base"), child);
  ASSERT_FALSE(prior.ok());
  ASSERT_EQ(prior.diagnostics().size(), 1u);
  EXPECT_THAT(prior.diagnostics().front(),
              DiagnosticAt(child, 2, 14, "ambiguous prior name 'Base'"));
  EXPECT_THAT(prior.error(), HasSubstr("a.prior"));
  EXPECT_THAT(prior.error(), HasSubstr("b.prior"));
}

TEST(PriorLibrarySpecializes, SameNameInDifferentDirectoriesIsNotAmbiguous) {
  TempDir own, library;
  WriteAll(own / "a.prior", Marked("Base", 1));
  WriteAll(library / "b.prior", Marked("Base", 2));
  EXPECT_TRUE(
      PriorLibrary({library.path()}).CompileText(Child("Base"), (own / "c.prior").string()).ok());
}

TEST(PriorLibrarySpecializes, UnknownParentIsLocatedAtTheName) {
  TempDir dir;
  const std::string child = (dir / "c.prior").string();
  const Result<CompiledPrior> prior = PriorLibrary().CompileText(Child("Nonexistent prior"), child);
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.diagnostics().front(),
              DiagnosticAt(child, 2, 14, "unknown prior 'Nonexistent prior'"));
}

// --- PRIORMAP_PRIOR_PATH -----------------------------------------------------------------------

TEST(PriorLibraryEnvironment, PriorPathListsItsDirectoriesWithoutEmptyEntries) {
  const ScopedEnvironment env("PRIORMAP_PRIOR_PATH", "/one::/two/three:");
  EXPECT_THAT(PriorLibrary::EnvironmentPriorPath(),
              ElementsAre(fs::path("/one"), fs::path("/two/three")));
}

TEST(PriorLibraryEnvironment, UnsetOrEmptyPriorPathHasNoDirectories) {
  {
    const ScopedEnvironment env("PRIORMAP_PRIOR_PATH", std::nullopt);
    EXPECT_TRUE(PriorLibrary::EnvironmentPriorPath().empty());
  }
  const ScopedEnvironment env("PRIORMAP_PRIOR_PATH", "");
  EXPECT_TRUE(PriorLibrary::EnvironmentPriorPath().empty());
}

TEST(PriorLibraryEnvironment, PriorsInThePriorPathCanBeLoadedByName) {
  TempDir dir;
  WriteAll(dir / "env.prior", Marked("From the environment", 5));
  const ScopedEnvironment env("PRIORMAP_PRIOR_PATH", dir.path().string());
  const PriorLibrary library(PriorLibrary::EnvironmentPriorPath());
  const Result<CompiledPrior> prior = library.Load("From the environment");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(MarkerOf(prior.value()), "5");
  EXPECT_FALSE(PriorLibrary().Load("From the environment").ok());  // not without the path
}

// --- Load --------------------------------------------------------------------------------------

TEST(PriorLibraryLoad, FilePathNameAndStemGiveTheSamePrior) {
  const fs::path file = fs::path(PRIORMAP_PRIORS_DIR) / "polygonal.prior";
  const PriorLibrary library;
  const Result<CompiledPrior> by_path = library.Load(file.string());
  const Result<CompiledPrior> by_name = library.Load("Polygonal prior");
  const Result<CompiledPrior> by_stem = library.Load("polygonal");
  ASSERT_TRUE(by_path.ok()) << by_path.error();
  ASSERT_TRUE(by_name.ok()) << by_name.error();
  ASSERT_TRUE(by_stem.ok()) << by_stem.error();
  EXPECT_EQ(by_path.value().chain()[0].path, file.string());
  EXPECT_EQ(by_name.value().chain()[0].path, "<builtin>/polygonal.prior");
  EXPECT_EQ(by_stem.value().chain()[0].path, "<builtin>/polygonal.prior");
  for (const Result<CompiledPrior>* prior : {&by_path, &by_name, &by_stem}) {
    EXPECT_EQ(prior->value().name(), "Polygonal prior");
    const CompiledBlock& block = *prior->value().block(BlockKind::kSameRegion);
    ASSERT_EQ(block.num_terms(), 2);
    EXPECT_EQ(block.TermExpression(1),
              by_path.value().block(BlockKind::kSameRegion)->TermExpression(1));
  }
}

TEST(PriorLibraryLoad, StemOfAFileInALibraryDirectoryLoadsIt) {
  TempDir dir;
  WriteAll(dir / "corridor.prior", Marked("Corridor prior", 6));
  const Result<CompiledPrior> prior = PriorLibrary({dir.path()}).Load("corridor");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(prior.value().name(), "Corridor prior");
}

TEST(PriorLibraryLoad, LibraryDirectoryShadowsABuiltinLoadedByName) {
  TempDir dir;
  WriteAll(dir / "mine.prior", Marked("Splines prior", 8));
  const Result<CompiledPrior> prior = PriorLibrary({dir.path()}).Load("Splines prior");
  ASSERT_TRUE(prior.ok()) << prior.error();
  EXPECT_EQ(MarkerOf(prior.value()), "8");
}

TEST(PriorLibraryLoad, UnknownNameIsAnError) {
  const Result<CompiledPrior> prior = PriorLibrary().Load("no such prior");
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.error(), HasSubstr("no prior file or prior named 'no such prior'"));
}

// A directory is not a prior, and a user who gives one most likely meant --prior-path.
TEST(PriorLibraryLoad, ADirectoryIsNamedAsOne) {
  TempDir dir;
  const Result<CompiledPrior> prior = PriorLibrary().Load(dir.path().string());
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.error(),
              HasSubstr(dir.path().string() + ": error: a directory, not a prior file"));
  EXPECT_THAT(prior.error(), HasSubstr("--prior-path"));
}

// A prior in a file that does not parse cannot be found by its name; the error says which files
// were passed over and why, and the listing's Unparsable() names them too.
TEST(PriorLibraryLoad, APriorThatDoesNotParseIsNamedWhenItsNameIsNotFound) {
  TempDir dir;
  WriteAll(dir / "walls.prior", "name: My walls\norder: 2\npriorlet same_region:\n  rho_1 == *\n");
  WriteAll(dir / "kid.prior", "name: Kid\nspecializes: My walls\n");
  const PriorLibrary library({dir.path()});
  const std::string where = (dir / "walls.prior").string() + ":4:12";
  const Result<CompiledPrior> by_name = library.Load("My walls");
  ASSERT_FALSE(by_name.ok());
  EXPECT_THAT(by_name.error(), HasSubstr("no prior file or prior named 'My walls'"));
  EXPECT_THAT(by_name.error(), HasSubstr("passed over as they do not parse:\n  " + where));
  const Result<CompiledPrior> kid = library.Load((dir / "kid.prior").string());
  ASSERT_FALSE(kid.ok());
  EXPECT_THAT(kid.error(), HasSubstr("unknown prior 'My walls'"));
  EXPECT_THAT(kid.error(), HasSubstr(where));
  const std::vector<Diagnostic> unparsable = library.Unparsable();
  ASSERT_EQ(unparsable.size(), 1u);
  EXPECT_EQ(unparsable[0].Location(), where);
}

TEST(PriorLibraryLoad, AmbiguousNameInALibraryDirectoryIsAnError) {
  TempDir dir;
  WriteAll(dir / "a.prior", Marked("Twice", 1));
  WriteAll(dir / "b.prior", Marked("Twice", 2));
  const Result<CompiledPrior> prior = PriorLibrary({dir.path()}).Load("Twice");
  ASSERT_FALSE(prior.ok());
  EXPECT_THAT(prior.error(), HasSubstr("ambiguous prior name 'Twice'"));
}

// --- List --------------------------------------------------------------------------------------

const std::map<std::string, std::string>& BuiltinNames() {
  static const std::map<std::string, std::string> names = {
      {"Polygonal prior", "polygonal.prior"},
      {"Rectangular prior", "rectangular.prior"},
      {"Rectangular prior (relaxed)", "rectangular-relaxed.prior"},
      {"Rectangular prior (relaxed - alternative)", "rectangular-relaxed-alternative.prior"},
      {"Circular prior", "circular.prior"},
      {"Circular prior (with prior on radius)", "circular-radius.prior"},
      {"Splines prior", "splines.prior"},
      {"Manhattan prior", "manhattan.prior"},
      {"Octagonal prior", "octagonal.prior"},
      {"Straight or circular prior", "straight-or-circular.prior"}};
  return names;
}

TEST(PriorLibraryList, ListsEveryBuiltinWithADescription) {
  const std::vector<PriorListing> listing = PriorLibrary().List();
  ASSERT_EQ(listing.size(), BuiltinNames().size());
  for (const PriorListing& p : listing) {
    ASSERT_TRUE(BuiltinNames().count(p.name)) << p.name;
    EXPECT_EQ(p.path, "<builtin>/" + BuiltinNames().at(p.name));
    EXPECT_TRUE(p.builtin);
    EXPECT_FALSE(p.description.empty()) << p.name;
    EXPECT_LE(p.description.size(), 100u) << p.name;
  }
}

TEST(PriorLibraryList, DescriptionIsTheFirstSentenceOfTheLeadingComment) {
  TempDir dir;
  WriteAll(dir / "d.prior",
           "# A prior for tests: walls are described here. More words follow\n# on the next "
           "line.\nname: D\norder: "
           "1\n");
  const std::vector<PriorListing> listing = PriorLibrary({dir.path()}).List();
  ASSERT_FALSE(listing.empty());
  EXPECT_EQ(listing.front().name, "D");
  EXPECT_EQ(listing.front().description, "A prior for tests: walls are described here.");
  EXPECT_FALSE(listing.front().builtin);
}

TEST(PriorLibraryList, AFileStartingWithAByteOrderMarkIsListedWithItsDescription) {
  TempDir dir;
  WriteAll(dir / "bom.prior", "\xEF\xBB\xBF# Written with Notepad. More\nname: Bom\norder: 1\n");
  const PriorLibrary library({dir.path()});
  EXPECT_THAT(library.Unparsable(), ::testing::IsEmpty());
  const std::vector<PriorListing> listing = library.List();
  ASSERT_FALSE(listing.empty());
  EXPECT_EQ(listing.front().name, "Bom");
  EXPECT_EQ(listing.front().description, "Written with Notepad.");
}

// The leading comment ends where the lexer ends lines: with CR-only endings it is not the whole
// file.
TEST(PriorLibraryList, DescriptionEndsAtTheLineEndsTheLexerReads) {
  for (const std::string line_end : {"\r", "\r\n", "\r\r\n"}) {
    TempDir dir;
    WriteAll(dir / "cr.prior", "# Short." + line_end + "#  and more" + line_end + line_end +
                                   "name: Cr" + line_end + "order: 1" + line_end);
    const PriorLibrary library({dir.path()});
    EXPECT_THAT(library.Unparsable(), ::testing::IsEmpty());
    const std::vector<PriorListing> listing = library.List();
    ASSERT_FALSE(listing.empty());
    EXPECT_EQ(listing.front().name, "Cr");
    EXPECT_EQ(listing.front().description, "Short. and more") << ::testing::PrintToString(line_end);
  }
}

TEST(PriorLibraryList, DirectoriesComeFirstAndShadowedNamesAreListedOnce) {
  TempDir first, second;
  WriteAll(first / "mine.prior", Marked("Polygonal prior", 1));
  WriteAll(first / "extra.prior", Marked("Extra prior", 2));
  WriteAll(second / "again.prior", Marked("Polygonal prior", 3));
  WriteAll(second / "broken.prior", "this is not a prior\n");
  const std::vector<PriorListing> listing = PriorLibrary({first.path(), second.path()}).List();
  std::multiset<std::string> names;
  for (const PriorListing& p : listing) names.insert(p.name);
  EXPECT_EQ(names.count("Polygonal prior"), 1u);
  EXPECT_EQ(names.count("Extra prior"), 1u);
  EXPECT_EQ(listing.size(), BuiltinNames().size() + 1);
  const auto polygonal = std::find_if(listing.begin(), listing.end(), [](const PriorListing& p) {
    return p.name == "Polygonal prior";
  });
  ASSERT_NE(polygonal, listing.end());
  EXPECT_EQ(polygonal->path, (first / "mine.prior").string());
  EXPECT_FALSE(polygonal->builtin);
  // The directories' priors before the built-ins.
  EXPECT_FALSE(listing[0].builtin);
  EXPECT_FALSE(listing[1].builtin);
  EXPECT_TRUE(listing[2].builtin);
}

// --- the built-in library ----------------------------------------------------------------------

TEST(BuiltinPriors, TextsAreTheFilesOfThePriorsDirectory) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(PRIORMAP_PRIORS_DIR)) {
    if (entry.path().extension() == ".prior")
      files[entry.path().filename().string()] = ReadAll(entry.path());
  }
  std::map<std::string, std::string> builtin(BuiltinPriorTexts().begin(),
                                             BuiltinPriorTexts().end());
  EXPECT_EQ(builtin.size(), BuiltinPriorTexts().size()) << "a file name twice";
  EXPECT_EQ(builtin, files);
  EXPECT_EQ(files.size(), 10u);
}

TEST(BuiltinPriors, EveryBuiltinParsesAndCompiles) {
  const PriorLibrary library;
  for (const auto& [file, text] : BuiltinPriorTexts()) {
    const Result<PriorFile> parsed = ParsePrior(text, "<builtin>/" + file);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    const HeaderEntry* name = parsed.value().Header("name");
    ASSERT_NE(name, nullptr) << file;
    const Result<CompiledPrior> by_name = library.Load(name->value);
    ASSERT_TRUE(by_name.ok()) << by_name.error();
    EXPECT_EQ(by_name.value().name(), name->value);
    EXPECT_EQ(by_name.value().chain()[0].path, "<builtin>/" + file);
    int blocks = 0;
    for (int b = 0; b < kNumBlockKinds; ++b)
      blocks += by_name.value().block(static_cast<BlockKind>(b)) ? 1 : 0;
    EXPECT_GT(blocks, 0) << file;
    const Result<CompiledPrior> compiled = library.Compile(parsed.value());
    ASSERT_TRUE(compiled.ok()) << compiled.error();
    EXPECT_EQ(compiled.value().order(), by_name.value().order());
    EXPECT_THAT(compiled.value().warnings(), ::testing::IsEmpty()) << file;
  }
}

TEST(BuiltinPriors, FigureTwoPriorsHaveThePapersHeaderValuesAndParents) {
  const PriorLibrary library;
  struct Expected {
    std::string stem;
    int order;
    double max_curvature;
    std::vector<std::string> chain;
  };
  const std::vector<Expected> expected = {
      {"polygonal", 2, 0.0, {"Polygonal prior"}},
      {"rectangular", 2, 0.0, {"Rectangular prior", "Polygonal prior"}},
      {"rectangular-relaxed", 2, 0.0, {"Rectangular prior (relaxed)", "Polygonal prior"}},
      {"rectangular-relaxed-alternative",
       2,
       0.0,
       {"Rectangular prior (relaxed - alternative)", "Polygonal prior"}},
      {"circular", 3, 10.0, {"Circular prior"}},
      {"circular-radius", 3, 10.0, {"Circular prior (with prior on radius)", "Circular prior"}},
      {"splines", 2, 10.0, {"Splines prior"}}};
  for (const Expected& e : expected) {
    const Result<CompiledPrior> prior = library.Load(e.stem);
    ASSERT_TRUE(prior.ok()) << prior.error();
    EXPECT_EQ(prior.value().order(), e.order) << e.stem;
    EXPECT_EQ(prior.value().max_curvature(), e.max_curvature) << e.stem;
    std::vector<std::string> chain;
    for (const PriorOrigin& origin : prior.value().chain()) chain.push_back(origin.name);
    EXPECT_EQ(chain, e.chain);
  }
}

}  // namespace
}  // namespace priormap::dsl
