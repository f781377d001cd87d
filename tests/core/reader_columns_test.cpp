// Columns of the readers' diagnostics count characters, as an editor shows them, not bytes: a
// "Zürich café" before the offending value takes 11 columns, not 13. Each reader is checked on
// text holding UTF-8 before the error against the same text with ASCII letters in its place,
// which must give the same line and column; and on positions counted by hand.
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/csm_io.hpp>
#include <priormap/core/diagnostic.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/robond_sonar_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/utf8.hpp>

#include "testing/diagnostic_matchers.hpp"

namespace priormap {
namespace {

using testing::DiagnosticAt;
using ::testing::ElementsAre;

// `text` with every non-ASCII character (a 2-byte UTF-8 letter in these tests) made one 'x'.
std::string Ascii(std::string_view text) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const auto c = DecodeUtf8(text, at);
    out += c && c->length == 1 ? text[at] : 'x';
    at += c ? c->length : 1;
  }
  return out;
}

// The only diagnostic of a failed result.
template <typename T>
Diagnostic OnlyError(const Result<T>& result) {
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.diagnostics().size(), 1U) << result.error();
  return result.diagnostics().empty() ? Diagnostic{} : result.diagnostics().front();
}

// ---- the helpers ----

TEST(ReaderColumns, CharacterColumnCountsCharactersNotBytes) {
  EXPECT_EQ(CharacterColumn("caf\xc3\xa9 x", 6), 6);  // the 'x'
  EXPECT_EQ(CharacterColumn("caf\xc3\xa9 x", 7), 7);  // one past the end
  EXPECT_EQ(CharacterColumn("caf\xc3\xa9 x", 9), 9);  // and a column per byte beyond
  EXPECT_EQ(CharacterColumn("caf\xc3\xa9", 4), 4);    // inside the 'é': its column
  EXPECT_EQ(CharacterColumn("\xe2\x82\xac\xf0\x9f\x98\x80!", 7), 3);  // € (3 bytes), 😀 (4)
  EXPECT_EQ(CharacterColumn("a\xe9z", 2), 3);  // a byte that is not UTF-8 takes one column
  EXPECT_EQ(CharacterColumn("", 0), 1);
  EXPECT_EQ(CountCharacters("Z\xc3\xbcrich caf\xc3\xa9"), 11U);
  EXPECT_EQ(CountCharacters("\xff\xfe"), 2U);
}

TEST(ReaderColumns, QuotedTextShowsUtf8AsItIsAndEscapesTheRest) {
  EXPECT_EQ(QuoteForMessage("Z\xc3\xbcrich"), "'Z\xc3\xbcrich'");  // as the user wrote it
  EXPECT_EQ(QuoteForMessage("\xe2\x82\xac \xf0\x9f\x98\x80"), "'\xe2\x82\xac \xf0\x9f\x98\x80'");
  // Bytes that are not UTF-8 (Latin-1, a cut sequence, a stray continuation byte).
  EXPECT_EQ(QuoteForMessage("caf\xe9"), "'caf\\xe9'");
  EXPECT_EQ(QuoteForMessage("\xe2\x82"), "'\\xe2\\x82'");
  EXPECT_EQ(QuoteForMessage("\x80z"), "'\\x80z'");
  // Controls (C0, DEL, C1 U+0085) and invisible format characters (U+202E right-to-left
  // override, U+200B zero-width space, the byte order mark), byte by byte.
  EXPECT_EQ(QuoteForMessage("a\tb\x7f"), "'a\\x09b\\x7f'");
  EXPECT_EQ(QuoteForMessage("\xc2\x85"), "'\\xc2\\x85'");
  EXPECT_EQ(QuoteForMessage("x\xe2\x80\xaey"), "'x\\xe2\\x80\\xaey'");
  EXPECT_EQ(QuoteForMessage("\xe2\x80\x8b\xef\xbb\xbf"), "'\\xe2\\x80\\x8b\\xef\\xbb\\xbf'");
  // Spaces other than ASCII's, which would read as a plain blank (U+00A0 no-break space after a
  // name, U+202F narrow no-break space in a French "1 000"), and more invisible ones (a variation
  // selector, a tag character, a line separator).
  EXPECT_EQ(QuoteForMessage("range\xc2\xa0"), "'range\\xc2\\xa0'");
  EXPECT_EQ(QuoteForMessage("1\xe2\x80\xaf"
                            "000"),
            "'1\\xe2\\x80\\xaf000'");
  EXPECT_EQ(QuoteForMessage("a\xef\xb8\x8f\xf3\xa0\x80\x81\xe2\x80\xa8"),
            "'a\\xef\\xb8\\x8f\\xf3\\xa0\\x80\\x81\\xe2\\x80\\xa8'");
  // A combining mark (U+0301 acute) shows on the character before it, but is escaped where it
  // would draw on the opening quote or on an escape.
  EXPECT_EQ(QuoteForMessage("cafe\xcc\x81"), "'cafe\xcc\x81'");
  EXPECT_EQ(QuoteForMessage("e\xcc\x81\xcc\x81"), "'e\xcc\x81\xcc\x81'");
  EXPECT_EQ(QuoteForMessage("\xcc\x81x"), "'\\xcc\\x81x'");
  EXPECT_EQ(QuoteForMessage("\t\xcc\x81"), "'\\x09\\xcc\\x81'");
  EXPECT_EQ(QuoteForMessage("\xe9\xcc\x81"), "'\\xe9\\xcc\\x81'");
  // The limit counts characters: three 'ü' are three, not six.
  EXPECT_EQ(QuoteForMessage("\xc3\xbc\xc3\xbc\xc3\xbc\xc3\xbc", 3),
            "'\xc3\xbc\xc3\xbc\xc3\xbc...'");
  EXPECT_EQ(QuoteForMessage("abcd", 4), "'abcd'");
  EXPECT_EQ(QuoteForMessage("abcd", 0), "'...'");
  EXPECT_EQ(QuoteForMessage("\xe2\x80\x8bz\xe9y", 2),
            "'\\xe2\\x80\\x8bz...'");  // escaped, counted once
  EXPECT_EQ(QuoteForMessage(std::string(100, '7'), 40), fmt::format("'{:7<40}...'", ""));
}

TEST(ReaderColumns, ColumnCounterAgreesWithCharacterColumnWalkingForward) {
  // ASCII, 2-, 3- and 4-byte characters, a byte that is not UTF-8, and offsets past the end.
  const std::string_view line = "a\xc3\xa9 \xe2\x82\xac\xf0\x9f\x98\x80\xffz";
  const std::vector<std::size_t> starts = {0, 1, 3, 4, 7, 11, 12, 13, 15};
  ColumnCounter walked(line);
  for (const std::size_t offset : starts)
    EXPECT_EQ(walked.At(offset), CharacterColumn(line, offset)) << "offset " << offset;
  // Asked again where it stands, and with steps skipped.
  ColumnCounter skipping(line);
  EXPECT_EQ(skipping.At(0), 1);
  EXPECT_EQ(skipping.At(0), 1);
  EXPECT_EQ(skipping.At(7), 5);
  EXPECT_EQ(skipping.At(14), 9);
  EXPECT_EQ(skipping.At(16), 11);
}

TEST(ReaderColumns, CharacterColumnInTextCountsFromItsLineAndSkipsAByteOrderMark) {
  const std::string text = "\xc3\xa9\xc3\xa9\n\xc3\xa9 x";
  EXPECT_EQ(CharacterColumnInText(text, 2), 2);
  EXPECT_EQ(CharacterColumnInText(text, 4), 3);  // the newline ends line 1
  EXPECT_EQ(CharacterColumnInText(text, 5), 1);
  EXPECT_EQ(CharacterColumnInText(text, 8), 3);
  EXPECT_EQ(CharacterColumnInText(text, 100), 4);  // clamped to the end
  EXPECT_EQ(CharacterColumnInText("\xef\xbb\xbfx y", 5), 3);
}

// ---- JSON (priormap.log, priormap.scan, priormap.scene) ----

TEST(ReaderColumns, JsonSyntaxErrorAfterUtf8TextCountsCharacters) {
  const std::string text = R"({"format": "priormap.log", "comment": "Z)"
                           "\xc3\xbc"
                           R"(rich caf)"
                           "\xc3\xa9"
                           R"(", x})";
  const Diagnostic d = OnlyError(ParseJsonLog(text, "a.json"));
  EXPECT_EQ(d.line, 1);
  EXPECT_EQ(d.col, 54);  // 2 less than the byte's column
  const Diagnostic ascii = OnlyError(ParseJsonLog(Ascii(text), "a.json"));
  EXPECT_EQ(d.col, ascii.col);
  EXPECT_EQ(d.line, ascii.line);
}

TEST(ReaderColumns, JsonSchemaErrorAfterUtf8TextCountsCharacters) {
  const std::string text =
      "{\"format\": \"priormap.scan\", \"version\": 1, \"channel\": \"Z\xc3\xbcrich caf\xc3\xa9\", "
      "\"pose\": [0, 0, \"north\"], \"angles\": [0], \"ranges\": [1]}\n";
  const Diagnostic d = OnlyError(ParseJsonLog(text, "a.json"));
  EXPECT_THAT(std::vector<Diagnostic>{d},
              ElementsAre(DiagnosticAt("a.json", 1, 84, "expected theta (a number)")));
  EXPECT_EQ(d.col, OnlyError(ParseJsonLog(Ascii(text), "a.json")).col);
  // The same on a later line, after UTF-8 on an earlier one.
  const std::string two_lines =
      "{\"format\": \"priormap.scan\", \"channel\": \"\xc3\xa9\xc3\xa9\xc3\xa9\",\n"
      "  \"version\": 1, \"pose\": [0, 0, \"\xc3\xa9\"], \"angles\": [0], \"ranges\": [1]}\n";
  EXPECT_THAT(ParseJsonLog(two_lines, "a.json").diagnostics(),
              ElementsAre(DiagnosticAt("a.json", 2, 32, "expected theta (a number)")));
}

TEST(ReaderColumns, JsonNotUtf8ByteAfterUtf8TextIsAtItsCharacter) {
  // "caf\u00e9" is 4 characters, 5 bytes: the control character after it is at column 33.
  const Diagnostic d =
      OnlyError(ParseJsonLog("{\"format\": \"priormap.log\", \"caf\xc3\xa9\x01\": 1}", "a.json"));
  EXPECT_EQ(d.col, 33);
  const Diagnostic latin1 = OnlyError(
      ParseJsonLog("{\"format\": \"priormap.log\", \"\xc3\xa9\": \"caf\xe9\"}", "a.json"));
  EXPECT_EQ(latin1.col, 37);  // the byte 0xe9 itself, after a 1-character key
}

TEST(ReaderColumns, JsonSceneErrorAfterUtf8TextCountsCharacters) {
  const std::string text =
      "{\"format\": \"priormap.scene\", \"version\": 1, \"name\": \"B\xc3\xbcro\", "
      "\"surfaces\": [{\"type\": \"circle\", \"center\": [0, 0], \"radius\": 0}]}";
  const Result<Scene> scene = ParseJsonScene(text, "s.json");
  const Diagnostic d = OnlyError(scene);
  EXPECT_EQ(d.line, 1);
  EXPECT_EQ(d.col, OnlyError(ParseJsonScene(Ascii(text), "s.json")).col);
  EXPECT_EQ(d.col, static_cast<int>(text.find("0}]}")) + 1 - 1);  // one 2-byte letter before
}

// A byte order mark is not part of the document: a value is still located after it (the locator
// used to stop at it, leaving schema errors without a line), and columns of line 1 do not count
// it.
TEST(ReaderColumns, JsonByteOrderMarkNeitherHidesNorShiftsPositions) {
  const std::string doc =
      R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, "x"], "angles": [0], "ranges": [1]})";
  const Diagnostic plain = OnlyError(ParseJsonLog(doc, "a.json"));
  const Diagnostic marked = OnlyError(ParseJsonLog("\xef\xbb\xbf" + doc, "a.json"));
  EXPECT_EQ(plain.line, 1);
  EXPECT_EQ(plain.col, 58);
  EXPECT_EQ(marked.line, plain.line);
  EXPECT_EQ(marked.col, plain.col);
  EXPECT_EQ(marked.message, plain.message);

  const std::string bad =
      R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, x], "angles": [0], "ranges": [1]})";
  const Diagnostic syntax = OnlyError(ParseJsonLog("\xef\xbb\xbf" + bad, "a.json"));
  EXPECT_EQ(syntax.col, OnlyError(ParseJsonLog(bad, "a.json")).col);
  EXPECT_EQ(syntax.col, 58);
}

// ---- CSM laser_data ----

TEST(ReaderColumns, CsmErrorAfterUtf8TextCountsCharacters) {
  const std::string text =
      "{\"comment\": \"Z\xc3\xbcrich caf\xc3\xa9\", \"nrays\": \"two\", \"readings\": [1, 2]}\n";
  const Diagnostic d = OnlyError(ParseCsmLog(text, "c.json"));
  EXPECT_THAT(std::vector<Diagnostic>{d}, ElementsAre(DiagnosticAt("c.json", 1, 37, "\"nrays\"")));
  EXPECT_EQ(d.col, OnlyError(ParseCsmLog(Ascii(text), "c.json")).col);
  // An object after one holding UTF-8 on the same line: its columns add up in characters.
  const std::string first =
      "{\"nrays\": 1, \"theta\": [0], \"readings\": [1], \"odometry\": [0, 0, 0], \"note\": "
      "\"\xc3\xa9\xc3\xa9\"}";
  const std::string second = R"({"nrays": 2, "readings": [1, 2, 3], "odometry": [0, 0, 0]})";
  const Diagnostic later = OnlyError(ParseCsmLog(first + " " + second, "c.json"));
  EXPECT_EQ(later.col, static_cast<int>(first.size()) - 2 + 1 + 26);
  EXPECT_EQ(later.col, OnlyError(ParseCsmLog(Ascii(first) + " " + second, "c.json")).col);
}

// ---- CARMEN ----

TEST(ReaderColumns, CarmenErrorAfterAUtf8HostCountsCharacters) {
  // "ODOM 0 0 0 0 0 0 1.5 Zürich " is 28 characters, 29 bytes.
  const std::string bad_stamp = "ODOM 0 0 0 0 0 0 1.5 Z\xc3\xbcrich 2.x\n";
  EXPECT_THAT(ParseCarmenLog(bad_stamp, "c.log").diagnostics(),
              ElementsAre(DiagnosticAt("c.log", 1, 29, "expected logger_timestamp")));
  // A field missing at the end: the column after the last character.
  EXPECT_THAT(ParseCarmenLog("ODOM 0 0 0 0 0 0 1.5 Z\xc3\xbcrich\r\n", "c.log").diagnostics(),
              ElementsAre(DiagnosticAt("c.log", 1, 28, "ODOM record ends early")));
  EXPECT_THAT(ParseCarmenLog("ODOM 0 0 0 0 0 0 1.5 caf\xc3\xa9 2.5 extra", "c.log").diagnostics(),
              ElementsAre(DiagnosticAt("c.log", 1, 31, "unexpected extra field 'extra'")));
  for (const std::string& text :
       {bad_stamp, std::string("ODOM 0 0 0 0 0 0 1.5 \xc3\xa9\xc3\xa9 2.5 x y\n")}) {
    EXPECT_EQ(OnlyError(ParseCarmenLog(text, "c.log")).col,
              OnlyError(ParseCarmenLog(Ascii(text), "c.log")).col)
        << text;
  }
}

TEST(ReaderColumns, CarmenTextNotUtf8AfterUtf8IsLocatedAtItsCharacter) {
  CarmenReadStats stats;
  ASSERT_TRUE(ParseCarmenLog("PARAM place Z\xc3\xbcrich\xfc\n", "c.log", {}, &stats).ok());
  ASSERT_TRUE(stats.not_utf8.has_value());
  EXPECT_EQ(stats.not_utf8->col, 19);  // "PARAM place Zürich" is 18 characters
  CarmenReadStats host;
  ASSERT_TRUE(
      ParseCarmenLog("ODOM 0 0 0 0 0 0 1.5 \xc3\xa9h\xf6st 1.5\n", "c.log", {}, &host).ok());
  ASSERT_TRUE(host.not_utf8.has_value());
  EXPECT_EQ(host.not_utf8->col, 24);
}

// ---- RoboND sonar ----

TEST(ReaderColumns, RoboNdErrorAfterUtf8TextCountsCharacters) {
  // Ten fields: the tenth is reported, after a field holding a 2-byte letter.
  const std::string z = "100 \xc3\xa9 5110 5110 5110 5110 5110 5110 5110 5110\n";
  const Result<Log> read = ParseRoboNdSonar(z, "m.txt", "100 0 0 0\n", "p.txt");
  EXPECT_THAT(read.diagnostics(), ElementsAre(DiagnosticAt("m.txt", 1, 42, "found more: '5110'")));
  EXPECT_EQ(OnlyError(read).col,
            OnlyError(ParseRoboNdSonar(Ascii(z), "m.txt", "100 0 0 0\n", "p.txt")).col);
  // A missing field: the column after the last character.
  EXPECT_THAT(ParseRoboNdSonar("100 5110 5110 5110 5110 5110 5110 5110 5110\n", "m.txt",
                               "100 \xc3\xa9\xc3\xa9\n", "p.txt")
                  .diagnostics(),
              ElementsAre(DiagnosticAt("p.txt", 1, 7, "expected 4 fields")));
}

}  // namespace
}  // namespace priormap
