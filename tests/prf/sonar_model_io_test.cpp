// Sonar model files ("priormap.sonar_model", version 1): a written model reads back bit for bit;
// a parameter left out keeps its default; each problem (an unknown key, a string for a number,
// another format or version, weights that are not a distribution) is one Diagnostic at the line
// and column of the offending value, saying what is wrong.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/prf/sonar_model_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Matcher;

constexpr const char* kName = "model.json";

// Every parameter, by its name in the file (docs/formats.md): written out here, not taken from
// kSonarModelParameters, so that a key renamed there breaks the round trip below.
const std::vector<std::pair<std::string, double SonarModel::*>> kParameters = {
    {"corner_bias", &SonarModel::corner_bias},
    {"corner_per_m", &SonarModel::corner_per_m},
    {"concave_corner_bias", &SonarModel::concave_corner_bias},
    {"face_bias", &SonarModel::face_bias},
    {"face_per_m", &SonarModel::face_per_m},
    {"face_per_rad_projection", &SonarModel::face_per_rad_projection},
    {"face_per_rad_subtended", &SonarModel::face_per_rad_subtended},
    {"max_return", &SonarModel::max_return},
    {"sigma_relative", &SonarModel::sigma_relative},
    {"sigma_min", &SonarModel::sigma_min},
    {"uniform_weight", &SonarModel::uniform_weight},
    {"exponential_weight", &SonarModel::exponential_weight},
    {"max_weight", &SonarModel::max_weight},
    {"exponential_rate", &SonarModel::exponential_rate},
    {"clear_uniform_weight", &SonarModel::clear_uniform_weight},
    {"clear_exponential_weight", &SonarModel::clear_exponential_weight},
    {"clear_max_weight", &SonarModel::clear_max_weight},
    {"multipath_weight", &SonarModel::multipath_weight},
    {"multipath_sigma_relative", &SonarModel::multipath_sigma_relative},
};

void ExpectSameBits(const SonarModel& actual, const SonarModel& expected) {
  for (const auto& [name, member] : kParameters)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(actual.*member),
              std::bit_cast<std::uint64_t>(expected.*member))
        << name << ": " << actual.*member << " vs " << expected.*member;
}

Matcher<const Diagnostic&> DiagnosticAt(int line, int col, const std::string& message_part) {
  return testing::DiagnosticAt(kName, line, col, message_part);
}

// A document with one member per line: format (line 2), version (line 3), then `members` from
// line 4 on. A value starts at column 7 + the length of its key.
std::string Document(const std::vector<std::pair<std::string, std::string>>& members,
                     const std::string& format = "\"priormap.sonar_model\"",
                     const std::string& version = "1") {
  std::string text = "{\n  \"format\": " + format + ",\n  \"version\": " + version;
  for (const auto& [key, value] : members) text += ",\n  \"" + key + "\": " + value;
  return text + "\n}\n";
}

std::vector<Diagnostic> Errors(const std::string& text) {
  const Result<SonarModel> result = ParseSonarModel(text, kName);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

// A valid model whose every parameter differs from its default and most need all 17 digits.
SonarModel Unusual() {
  SonarModel m;
  m.corner_bias = 0.1 + 0.2;
  m.corner_per_m = -1.0 / 3.0;
  m.concave_corner_bias = 2.0 / 7.0;
  m.face_bias = -std::nextafter(1.0, 2.0);
  m.face_per_m = -1e-300;
  m.face_per_rad_projection = 17.123456789012345;
  m.face_per_rad_subtended = std::sqrt(2.0) * 8.0;
  m.max_return = 0.9 + 1e-16 * 3.0;
  m.sigma_relative = 0.0;
  m.sigma_min = std::numeric_limits<double>::min();  // the smallest normal double
  m.uniform_weight = 1.0 / 3.0;
  m.exponential_weight = 1.0 / 7.0;
  m.max_weight = 1.0 - 1.0 / 3.0 - 1.0 / 7.0;
  m.exponential_rate = std::exp(1.0);
  m.clear_uniform_weight = 0.1;
  m.clear_exponential_weight = 0.0;
  m.clear_max_weight = 0.9;
  m.multipath_weight = 0.1 + 0.3;
  m.multipath_sigma_relative = 1.0 / 70.0;
  return m;
}

TEST(SonarModelIo, AWrittenModelReadsBackBitForBit) {
  // The list above is every parameter: one added to the model must be added here too.
  ASSERT_EQ(kParameters.size(), kSonarModelParameters.size());
  const SonarModel model = Unusual();
  ASSERT_EQ(model.Problem(), "");
  const SonarModel defaults;
  for (const auto& [name, member] : kParameters)
    ASSERT_NE(model.*member, defaults.*member) << name << " would not show a lost value";
  const std::string text = FormatSonarModel(model);
  for (const auto& [name, member] : kParameters)
    EXPECT_THAT(text, HasSubstr("\"" + name + "\"")) << "every parameter is written";
  const Result<SonarModel> read = ParseSonarModel(text, kName);
  ASSERT_TRUE(read.ok()) << read.error();
  ExpectSameBits(read.value(), model);
  EXPECT_EQ(FormatSonarModel(read.value()), text);
}

TEST(SonarModelIo, TheFitRecordIsKeptInTheFileAndIgnoredOnReading) {
  const nlohmann::ordered_json about = {{"readings", 1234}, {"log_likelihood", -56.5}};
  const std::string text = FormatSonarModel(Unusual(), &about);
  EXPECT_THAT(text, HasSubstr("\"fit\""));
  EXPECT_THAT(text, HasSubstr("1234"));
  const Result<SonarModel> read = ParseSonarModel(text, kName);
  ASSERT_TRUE(read.ok()) << read.error();
  ExpectSameBits(read.value(), Unusual());
}

TEST(SonarModelIo, WriteAndReadAFile) {
  testing::TempDir dir;
  const auto path = dir / "fitted.json";
  const nlohmann::ordered_json about = {{"scene", "office"}};
  WriteSonarModel(Unusual(), path, &about);
  EXPECT_FALSE(testing::HasTemporaryFile(dir.path()));
  const Result<SonarModel> read = ReadSonarModel(path);
  ASSERT_TRUE(read.ok()) << read.error();
  ExpectSameBits(read.value(), Unusual());
  // Problems name the file.
  testing::WriteAll(path, Document({{"face_bias", "true"}}));
  const Result<SonarModel> bad = ReadSonarModel(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.diagnostics(),
              ElementsAre(testing::DiagnosticAt(path.string(), 4, 16, "\"face_bias\"")));
  const Result<SonarModel> missing = ReadSonarModel(dir / "none.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.diagnostics().at(0).file, (dir / "none.json").string());
}

TEST(SonarModelIo, LeftOutParametersKeepTheirDefaults) {
  const Result<SonarModel> bare = ParseSonarModel(Document({}), kName);
  ASSERT_TRUE(bare.ok()) << bare.error();
  ExpectSameBits(bare.value(), SonarModel{});
  const Result<SonarModel> some =
      ParseSonarModel(Document({{"face_bias", "-2.5"}, {"concave_corner_bias", "1"}}), kName);
  ASSERT_TRUE(some.ok()) << some.error();
  SonarModel expected;
  expected.face_bias = -2.5;
  expected.concave_corner_bias = 1.0;
  ExpectSameBits(some.value(), expected);
}

TEST(SonarModelIo, AnUnknownKeyIsAnErrorAtItsValue) {
  // A misspelt name: "corner_bais" (11 characters) on line 5, its value at column 18.
  EXPECT_THAT(Errors(Document({{"face_bias", "0.5"}, {"corner_bais", "2.0"}})),
              ElementsAre(DiagnosticAt(5, 18, "unknown sonar model parameter \"corner_bais\"")));
  // The message lists the names there are.
  EXPECT_THAT(Errors(Document({{"sigma", "0.1"}})),
              ElementsAre(DiagnosticAt(4, 12, "clear_exponential_weight")));
}

TEST(SonarModelIo, AStringForANumberIsAnErrorAtTheValue) {
  // "face_per_m" (10 characters): the value at column 17.
  EXPECT_THAT(Errors(Document({{"face_bias", "1"}, {"face_per_m", "\"steep\""}})),
              ElementsAre(DiagnosticAt(5, 17, "expected \"face_per_m\" (a number)")));
  // Non-finite values, which the reader's number syntax allows elsewhere, are refused.
  EXPECT_THAT(Errors(Document({{"corner_bias", "\"inf\""}})),
              ElementsAre(DiagnosticAt(4, 18, "finite")));
  EXPECT_THAT(Errors(Document({{"corner_bias", "null"}})),
              ElementsAre(DiagnosticAt(4, 18, "finite")));
  EXPECT_THAT(Errors(Document({{"max_weight", "[0.6]"}})),
              ElementsAre(DiagnosticAt(4, 17, "\"max_weight\"")));
}

TEST(SonarModelIo, AnotherFormatOrVersionIsAnErrorAtItsValue) {
  EXPECT_THAT(Errors(Document({}, "\"priormap.scene\"")),
              ElementsAre(DiagnosticAt(
                  2, 13, "expected format \"priormap.sonar_model\", got \"priormap.scene\"")));
  EXPECT_THAT(Errors(Document({}, "\"priormap.sonar_model\"", "2")),
              ElementsAre(DiagnosticAt(3, 14, "unsupported priormap.sonar_model version 2")));
  EXPECT_THAT(Errors("{\"version\": 1}"),
              ElementsAre(DiagnosticAt(1, 1, "missing key \"format\"")));
  EXPECT_THAT(Errors("[1, 2]"), ElementsAre(DiagnosticAt(1, 1, "an object")));
  EXPECT_THAT(Errors("{\"format\": \"priormap.sonar_model\",\n \"version\": 1,}"),
              ElementsAre(DiagnosticAt(2, 15, "invalid JSON")));
}

TEST(SonarModelIo, WeightsThatAreNotADistributionAreAnError) {
  // Reported for the document as a whole (no one value is wrong by itself).
  EXPECT_THAT(Errors(Document({{"uniform_weight", "0.5"}})),
              ElementsAre(DiagnosticAt(1, 1, "sum to")));
  EXPECT_THAT(Errors(Document({{"uniform_weight", "0.5"}})),
              ElementsAre(DiagnosticAt(1, 1, "not a usable sonar model")));
  EXPECT_THAT(Errors(Document({{"clear_uniform_weight", "0"}, {"clear_max_weight", "0.9"}})),
              ElementsAre(DiagnosticAt(1, 1, "clear outlier weights")));
}

TEST(SonarModelIo, AParameterOutOfItsRangeIsAnErrorAtItsValue) {
  // "max_return" (10 characters): the value at column 17.
  EXPECT_THAT(Errors(Document({{"face_bias", "1"}, {"max_return", "1"}})),
              ElementsAre(DiagnosticAt(5, 17, "not a usable sonar model: max_return 1 is not")));
  EXPECT_THAT(Errors(Document({{"exponential_rate", "-2"}})),
              ElementsAre(DiagnosticAt(4, 23, "exponential_rate -2 is not positive")));
}

TEST(SonarModelIo, UnknownKeysWithPointerCharactersAreLocated) {
  // Keys are JSON pointer tokens in the diagnostics: '/' and '~' are escaped there, and the
  // location must still be found in the text.
  EXPECT_THAT(Errors(Document({{"a/b", "1"}})), ElementsAre(DiagnosticAt(4, 10, "\"a/b\"")));
  EXPECT_THAT(Errors(Document({{"a~b", "1"}})), ElementsAre(DiagnosticAt(4, 10, "\"a~b\"")));
}

TEST(SonarModelIo, AnUnknownKeyWrittenWithAnEscapeIsLocated) {
  // JSON lets a key be spelt with escapes ("\u005f" is '_'): the diagnostic must point at its
  // value all the same, not at line 0.
  EXPECT_THAT(Errors(Document({{"face\\u005fbias_x", "1"}})),
              ElementsAre(DiagnosticAt(4, 23, "face_bias_x")));
  EXPECT_THAT(Errors(Document({{"a\\tb", "1"}})), ElementsAre(DiagnosticAt(4, 11, "unknown")));
}

// The fitted model shipped as examples/formats/sonar-model-simulated.json (docs/sonar.md) reads,
// with the fit's record ignored, the corner reflectors' bias and the multipath weight it was
// fitted for (the simulator's multipath probability is 0.4).
TEST(SonarModelIo, ReadsTheShippedFittedModel) {
  const Result<SonarModel> model =
      ReadSonarModel(PRIORMAP_EXAMPLES_DIR "/formats/sonar-model-simulated.json");
  ASSERT_TRUE(model.ok()) << model.error();
  EXPECT_GT(model.value().concave_corner_bias, 1.0);
  EXPECT_GT(model.value().clear_max_weight, 0.9);
  EXPECT_NEAR(model.value().multipath_weight, 0.4, 0.05);
}

}  // namespace
}  // namespace priormap::prf
