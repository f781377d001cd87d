// The map_server YAML as a YAML parser reads it: the image name comes back as the PGM's file name
// whatever characters it holds, and values map_server refuses are never written.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/map_server.hpp>

#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

void AppendUtf8(std::uint32_t code, std::string& out) {
  if (code < 0x80) {
    out += static_cast<char>(code);
  } else if (code < 0x800) {
    out += static_cast<char>(0xC0 | code >> 6);
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else if (code < 0x10000) {
    out += static_cast<char>(0xE0 | code >> 12);
    out += static_cast<char>(0x80 | (code >> 6 & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | code >> 18);
    out += static_cast<char>(0x80 | (code >> 12 & 0x3F));
    out += static_cast<char>(0x80 | (code >> 6 & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  }
}

// A YAML scalar as a YAML 1.1 / 1.2 parser reads it, for the two styles the writer may use;
// nullopt for anything a parser would read otherwise or refuse. A plain scalar must not start with
// an indicator, hold ": " or " #", or have blanks at its ends (YAML 1.2, 7.3.3); a double-quoted
// one ends at its first unescaped '"' (7.3.1) and may hold no raw control character or line break.
std::optional<std::string> ParseYamlScalar(std::string_view text) {
  if (text.empty()) return std::nullopt;
  if (text.front() != '"') {
    if (std::string_view("-?:,[]{}#&*!|>'\"%@`").find(text.front()) != std::string_view::npos ||
        text.find(": ") != std::string_view::npos || text.find(" #") != std::string_view::npos ||
        text.back() == ' ' || text.back() == ':' || text.front() == ' ') {
      return std::nullopt;
    }
    for (char c : text) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return std::nullopt;
    }
    return std::string(text);
  }
  std::string out;
  for (std::size_t at = 1; at < text.size(); ++at) {
    const char c = text[at];
    if (c == '"') return at + 1 == text.size() ? std::optional<std::string>(out) : std::nullopt;
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return std::nullopt;
    // NEL, LS and PS are line breaks in YAML 1.1: a quoted scalar would fold them.
    for (std::string_view brk : {"\xC2\x85", "\xE2\x80\xA8", "\xE2\x80\xA9"}) {
      if (text.substr(at).starts_with(brk)) return std::nullopt;
    }
    if (c != '\\') {
      out += c;
      continue;
    }
    if (++at == text.size()) return std::nullopt;
    const char e = text[at];
    std::size_t digits = 0;
    if (e == '"' || e == '\\') {
      out += e;
    } else if (e == 'x') {
      digits = 2;
    } else if (e == 'u') {
      digits = 4;
    } else {
      return std::nullopt;  // the writer uses no other escape
    }
    if (digits == 0) continue;
    if (at + digits >= text.size()) return std::nullopt;
    const std::string hex(text.substr(at + 1, digits));
    if (hex.find_first_not_of("0123456789ABCDEFabcdef") != std::string::npos) return std::nullopt;
    AppendUtf8(static_cast<std::uint32_t>(std::stoul(hex, nullptr, 16)), out);
    at += digits;
  }
  return std::nullopt;  // no closing quote
}

// The image name the YAML file gives, as a YAML parser reads it.
std::optional<std::string> ImageOf(const std::string& yaml) {
  const std::string key = "image: ";
  if (!yaml.starts_with(key)) return std::nullopt;
  return ParseYamlScalar(std::string_view(yaml).substr(key.size(), yaml.find('\n') - key.size()));
}

OccupancyRaster SmallRaster() {
  OccupancyRaster raster;
  raster.probability = Eigen::MatrixXd::Constant(2, 3, 0.25);
  raster.origin = Vec2(-1.5, 2.0);
  raster.resolution = 0.1;
  return raster;
}

TEST(MapServerYaml, APlainFileNameIsWrittenAsMapSaverWritesIt) {
  testing::TempDir dir;
  WriteMapServerMap(dir / "grid.yaml", SmallRaster());
  EXPECT_EQ(testing::ReadAll(dir / "grid.yaml"),
            "image: grid.pgm\nresolution: 0.1\norigin: [-1.5, 2.0, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n");
}

// YAML 1.1's float (yaml.org/type/float.html), without the base-60 and special forms, which
// PyYAML and other YAML 1.1 parsers use: [-+]?([0-9][0-9_]*)?\.[0-9.]*([eE][-+][0-9]+)? -- a '.'
// is required, and an exponent's sign. Matched by hand: GCC 12's <regex> trips the ASan build's
// -Werror=maybe-uninitialized.
bool IsYaml11Float(const std::string& text) {
  std::size_t i = 0;
  const auto digit = [&](std::size_t at) {
    return at < text.size() && std::isdigit(static_cast<unsigned char>(text[at])) != 0;
  };
  const auto is = [&](std::size_t at, std::string_view chars) {
    return at < text.size() && chars.find(text[at]) != std::string_view::npos;
  };
  if (is(i, "-+")) ++i;
  if (digit(i)) {
    while (digit(i) || is(i, "_")) ++i;
  }
  if (!is(i, ".")) return false;
  while (digit(i) || is(i, ".")) ++i;
  if (is(i, "eE")) {
    ++i;
    if (!is(i, "-+")) return false;
    const std::size_t first = ++i;
    while (digit(i)) ++i;
    if (i == first) return false;
  }
  return i == text.size();
}

TEST(MapServerYaml, NumbersAreFloatsToYaml11Parsers) {
  // The shortest forms 1e-05, 1e+20 and 2 are a string, a string and an integer to PyYAML.
  for (const double value : {1e-5, 1e20, 2.0, -3.0, 0.0, -0.0, 0.1, 1.5e-7, 123456789.0}) {
    const std::string text = YamlFloat(value);
    EXPECT_TRUE(IsYaml11Float(text)) << text;
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), value) << text;
  }
  EXPECT_EQ(YamlFloat(1e-5), "1.0e-05");
  EXPECT_EQ(YamlFloat(2.0), "2.0");
  EXPECT_EQ(YamlFloat(0.05), "0.05");
  OccupancyRaster raster = SmallRaster();
  raster.resolution = 1e-5;
  raster.origin = Vec2(1e20, -4.0);
  testing::TempDir dir;
  WriteMapServerMap(dir / "grid.yaml", raster);
  EXPECT_THAT(testing::ReadAll(dir / "grid.yaml"),
              HasSubstr("resolution: 1.0e-05\norigin: [1.0e+20, -4.0, 0.0]\n"));
}

RC_GTEST_PROP(MapServerYaml, AnyFiniteNumberIsAFloatThatReadsBackExactly, ()) {
  const double value = *rc::gen::arbitrary<double>();
  RC_PRE(std::isfinite(value));
  const std::string text = YamlFloat(value);
  RC_ASSERT(IsYaml11Float(text));
  const double back = std::strtod(text.c_str(), nullptr);
  RC_ASSERT(back == value);
  RC_ASSERT(std::signbit(back) == std::signbit(value));
}

TEST(MapServerYaml, TheImageNameReadsBackAsThePgmsFileName) {
  const std::vector<std::string> stems = {"a #b",
                                          "a: b",
                                          "a:b",
                                          "*x",
                                          "&x",
                                          "!x",
                                          "'x",
                                          "\"x",
                                          "[x",
                                          "]x",
                                          "{x",
                                          "}x",
                                          "%x",
                                          "@x",
                                          "`x",
                                          "-x",
                                          "?x",
                                          "|x",
                                          ">x",
                                          ",x",
                                          "#x",
                                          " lead",
                                          "x\"y",
                                          "it's",
                                          "back\\slash",
                                          "tab\tand\nnewline",
                                          "carte ☃ 地図 naïve",
                                          "nel\xC2\x85ls\xE2\x80\xA8",
                                          "true",
                                          "null",
                                          "1.5",
                                          "~",
                                          "- x",
                                          ".hidden"};
  testing::TempDir dir;
  for (const std::string& stem : stems) {
    SCOPED_TRACE(stem);
    WriteMapServerMap(dir / (stem + ".yaml"), SmallRaster());
    const std::optional<std::string> image = ImageOf(testing::ReadAll(dir / (stem + ".yaml")));
    ASSERT_TRUE(image.has_value()) << testing::ReadAll(dir / (stem + ".yaml"));
    EXPECT_EQ(*image, stem + ".pgm");
    EXPECT_TRUE(fs::is_regular_file(dir / *image));
  }
}

TEST(MapServerYaml, QuotedNamesAreEscapedExactly) {
  EXPECT_EQ(YamlScalar("grid.pgm"), "grid.pgm");
  EXPECT_EQ(YamlScalar("a #b.pgm"), "\"a #b.pgm\"");
  EXPECT_EQ(YamlScalar("x\"y\\z.pgm"), "\"x\\\"y\\\\z.pgm\"");
  EXPECT_EQ(YamlScalar("it's.pgm"), "\"it's.pgm\"");
  EXPECT_EQ(YamlScalar("地図.pgm"), "\"地図.pgm\"");
  EXPECT_EQ(YamlScalar("a\tb\x7F\xC2\x85\xE2\x80\xA8.pgm"), "\"a\\x09b\\x7F\\x85\\u2028.pgm\"");
  EXPECT_EQ(YamlScalar("grid.yaml"), "\"grid.yaml\"");  // only .pgm names are known plain
  EXPECT_EQ(YamlScalar("\xFF.pgm"), std::nullopt);
  EXPECT_EQ(YamlScalar("\xC0\xAF.pgm"), std::nullopt);      // overlong '/'
  EXPECT_EQ(YamlScalar("\xED\xA0\x80.pgm"), std::nullopt);  // a surrogate
  EXPECT_EQ(YamlScalar("\xE2\x82.pgm"), std::nullopt);      // cut short
}

RC_GTEST_PROP(MapServerYaml, AnyUnicodeTextReadsBack, ()) {
  const auto codes = *rc::gen::container<std::vector<std::uint32_t>>(rc::gen::oneOf(
      rc::gen::inRange<std::uint32_t>(0, 0x80), rc::gen::inRange<std::uint32_t>(0x80, 0xD800),
      rc::gen::inRange<std::uint32_t>(0xE000, 0x110000)));
  std::string text;
  for (std::uint32_t code : codes) AppendUtf8(code, text);
  const std::optional<std::string> scalar = YamlScalar(text);
  RC_ASSERT(scalar.has_value());
  RC_ASSERT(ParseYamlScalar(*scalar) == std::optional<std::string>(text));
}

TEST(MapServerYaml, ValuesMapServerRefusesAreNeverWritten) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Case {
    double resolution, x, y;
    const char* message;
  };
  for (const Case& c :
       {Case{kNaN, 0, 0, "resolution = nan"}, Case{kInf, 0, 0, "resolution = inf"},
        Case{0.0, 0, 0, "resolution = 0,"}, Case{-0.05, 0, 0, "resolution = -0.05"},
        Case{0.05, kNaN, 0, "origin x = nan"}, Case{0.05, 0, -kInf, "origin y = -inf"},
        Case{0.05, kInf, 1e300, "origin x = inf"}}) {
    SCOPED_TRACE(c.message);
    testing::TempDir dir;
    OccupancyRaster raster = SmallRaster();
    raster.resolution = c.resolution;
    raster.origin = Vec2(c.x, c.y);
    try {
      WriteMapServerMap(dir / "grid.yaml", raster);
      ADD_FAILURE() << "written";
    } catch (const IoError& error) {
      EXPECT_THAT(error.what(), HasSubstr(c.message));
      EXPECT_THAT(error.what(), HasSubstr("grid.yaml"));
    }
    EXPECT_TRUE(testing::FilesIn(dir.path()).empty());
  }
}

TEST(MapServerYaml, AFileNameThatIsNotUtf8IsNeverWritten) {
  testing::TempDir dir;
  try {
    WriteMapServerMap(dir / "bad\xFF.yaml", SmallRaster());
    ADD_FAILURE() << "written";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("is not UTF-8"));
  }
  EXPECT_TRUE(testing::FilesIn(dir.path()).empty());
}

}  // namespace
}  // namespace priormap
