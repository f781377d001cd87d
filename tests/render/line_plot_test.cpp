#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/render/line_plot.hpp>

#include "testing/png_image.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::render {
namespace {

namespace fs = std::filesystem;
using priormap::testing::HasTemporaryFile;
using priormap::testing::Like;
using priormap::testing::PngImage;
using priormap::testing::ReadAll;
using priormap::testing::TempDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The widest run of columns without `color` between its first and last column.
int WidestGap(const std::set<int>& columns) {
  int gap = 0;
  for (auto it = columns.begin(); it != columns.end() && std::next(it) != columns.end(); ++it) {
    gap = std::max(gap, *std::next(it) - *it - 1);
  }
  return gap;
}

// Colours no default drawing uses (grid, text and the palette are other colours).
const Color kMagenta{1.0, 0.0, 1.0};
const Color kCrimson{0.8, 0.0, 0.2};

Series Xy(std::vector<double> x, std::vector<double> y, double width = 1.5) {
  Series series;
  series.x = std::move(x);
  series.y = std::move(y);
  series.width_px = width;
  return series;
}

// A line wide enough to cover whole pixels in its colour.
Series Line(std::vector<double> x, std::vector<double> y, const Color& color, double width = 4.0) {
  Series series = Xy(std::move(x), std::move(y), width);
  series.color = color;
  return series;
}

LinePlotOptions Size(int width, int height) {
  LinePlotOptions options;
  options.width_px = width;
  options.height_px = height;
  return options;
}

LinePlotOptions YRange(double lo, double hi) {
  LinePlotOptions options;
  options.y_range = std::pair{lo, hi};
  return options;
}

TEST(LinePlot, SavesPngSvgAndPdfWithTheRequestedSize) {
  const TempDir dir;
  LinePlotOptions options = Size(640, 360);
  options.title = "sizes";
  options.x_label = "x";
  options.y_label = "y";
  LinePlot plot(options);
  Series data = Xy({0, 1, 2, 3}, {1, 3, 2, 4});
  data.label = "data";
  plot.Add(data);
  plot.Save(dir / "p.png");
  plot.Save(dir / "p.svg");
  plot.Save(dir / "p.pdf");

  const PngImage image(dir / "p.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image.width(), 640);
  EXPECT_EQ(image.height(), 360);

  const std::string svg = ReadAll(dir / "p.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("width=\"640"), std::string::npos);
  EXPECT_NE(svg.find("height=\"360"), std::string::npos);

  const std::string pdf = ReadAll(dir / "p.pdf");
  EXPECT_TRUE(pdf.starts_with("%PDF"));
  EXPECT_NE(pdf.find("/MediaBox [ 0 0 640 360 ]"), std::string::npos);
  EXPECT_FALSE(HasTemporaryFile(dir.path()));
}

TEST(LinePlot, SeriesWithMismatchedSizesIsAContractErrorAndWritesNothing) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Xy({0, 1, 2}, {0, 1}));
  EXPECT_THROW(plot.Save(dir / "bad.png"), ContractError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(LinePlot, UnsupportedExtensionIsAnIoErrorAndWritesNothing) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Xy({0, 1}, {0, 1}));
  EXPECT_THROW(plot.Save(dir / "plot.jpg"), IoError);
  EXPECT_THROW(plot.Save(dir / "missing" / "plot.png"), IoError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(LinePlot, EmptyPlotStillSaves) {
  const TempDir dir;
  LinePlotOptions options = Size(300, 200);
  options.title = "nothing yet";
  const LinePlot plot(options);
  plot.Save(dir / "empty.png");
  plot.Save(dir / "empty.svg");
  const PngImage image(dir / "empty.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image.width(), 300);
  EXPECT_EQ(image.height(), 200);
}

TEST(LinePlot, AllNanOrConstantSeriesStillSave) {
  const TempDir dir;
  LinePlot all_nan;
  all_nan.Add(Xy({0, 1, 2}, {kNaN, kNaN, kNaN}));
  EXPECT_NO_THROW(all_nan.Save(dir / "nan.png"));
  LinePlot constant;
  constant.Add(Xy({5, 5}, {-2, -2}));
  EXPECT_NO_THROW(constant.Save(dir / "constant.png"));
  EXPECT_TRUE(PngImage(dir / "constant.png").ok());
}

// 0.1 * 3 and 0.3 differ in the last bit: a y range one double wide, with a tick step far below
// the spacing of doubles there (this used to loop forever, allocating ticks).
TEST(LinePlot, SeriesConstantUpToRoundingSaves) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Line({0, 1, 2}, {0.3, 0.1 * 3, 0.3}, kCrimson));
  plot.Save(dir / "rounding.png");
  EXPECT_GT(PngImage(dir / "rounding.png").Count(Like(kCrimson)), 100);
}

TEST(LinePlot, EmptyExplicitRangeIsAContractError) {
  const TempDir dir;
  LinePlotOptions options;
  options.x_range = std::pair{1.0, 1.0};
  LinePlot plot(options);
  plot.Add(Xy({0, 1}, {0, 1}));
  EXPECT_THROW(plot.Save(dir / "range.png"), ContractError);
}

TEST(LinePlot, SeriesColourAppearsInThePng) {
  const TempDir dir;
  LinePlot with;
  with.Add(Line({0, 1, 2, 3}, {0, 2, 1, 3}, kCrimson));
  with.Save(dir / "with.png");
  LinePlot without;
  without.Add(Xy({0, 1, 2, 3}, {0, 2, 1, 3}, 4.0));  // palette colour
  without.Save(dir / "without.png");
  EXPECT_GT(PngImage(dir / "with.png").Count(Like(kCrimson)), 100);
  EXPECT_EQ(PngImage(dir / "without.png").Count(Like(kCrimson)), 0);
}

TEST(LinePlot, SeriesWithoutColourTakesThePaletteColourOfItsIndex) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Xy({0, 1}, {0, 1}, 4.0));
  plot.Add(Xy({0, 1}, {1, 0}, 4.0));
  plot.Save(dir / "palette.png");
  const PngImage image(dir / "palette.png");
  EXPECT_GT(image.Count(Like(palette::Categorical(0))), 50);
  EXPECT_GT(image.Count(Like(palette::Categorical(1))), 50);
}

TEST(LinePlot, MarkersDrawDotsInTheSeriesColour) {
  const TempDir dir;
  LinePlot plot;
  Series dots = Line({0, 1, 2}, {0, 1, 0}, kCrimson, 3.0);
  dots.markers = true;
  plot.Add(dots);
  plot.Save(dir / "markers.png");
  const std::set<int> columns = PngImage(dir / "markers.png").ColumnsWith(Like(kCrimson));
  ASSERT_FALSE(columns.empty());
  // Three separate dots, no line between them.
  EXPECT_GT(WidestGap(columns), 100);
}

TEST(LinePlot, NanValuesBreakTheLine) {
  const TempDir dir;
  const std::vector<double> x = {0, 1, 2, 3, 4};
  LinePlot broken(YRange(-1.0, 1.0));
  broken.Add(Line(x, {0, 0, kNaN, 0, 0}, kCrimson));
  broken.Save(dir / "broken.png");
  LinePlot whole(YRange(-1.0, 1.0));
  whole.Add(Line(x, {0, 0, 0, 0, 0}, kCrimson));
  whole.Save(dir / "whole.png");

  const std::set<int> broken_columns = PngImage(dir / "broken.png").ColumnsWith(Like(kCrimson));
  const std::set<int> whole_columns = PngImage(dir / "whole.png").ColumnsWith(Like(kCrimson));
  ASSERT_FALSE(broken_columns.empty());
  ASSERT_FALSE(whole_columns.empty());
  const int span = *whole_columns.rbegin() - *whole_columns.begin();
  EXPECT_EQ(WidestGap(whole_columns), 0);
  // x in (1, 3) is not drawn: half of the line's span.
  EXPECT_GT(WidestGap(broken_columns), span * 4 / 10);
  EXPECT_LT(WidestGap(broken_columns), span * 6 / 10);
}

TEST(LinePlot, NanInXAlsoBreaksTheLine) {
  const TempDir dir;
  LinePlot plot(YRange(-1.0, 1.0));
  plot.Add(Line({0, 1, kNaN, 3, 4}, {0, 0, 0, 0, 0}, kCrimson));
  plot.Save(dir / "nan-x.png");
  const std::set<int> columns = PngImage(dir / "nan-x.png").ColumnsWith(Like(kCrimson));
  ASSERT_FALSE(columns.empty());
  EXPECT_GT(WidestGap(columns), (*columns.rbegin() - *columns.begin()) * 4 / 10);
}

TEST(LinePlot, HorizontalLinesAreInTheAutomaticYRange) {
  const TempDir dir;
  LinePlot automatic;
  automatic.Add(Xy({0, 1, 2}, {0.0, 0.5, 1.0}));
  automatic.AddHorizontalLine(10.0, kMagenta);  // no label: a legend swatch would count
  automatic.AddHorizontalLine(-10.0, kCrimson);
  automatic.Save(dir / "auto.png");
  const PngImage image(dir / "auto.png");
  EXPECT_GT(image.Count(Like(kMagenta)), 0);
  EXPECT_GT(image.Count(Like(kCrimson)), 0);

  // With a y range that excludes them, the lines are clipped away.
  LinePlot fixed(YRange(0.0, 1.0));
  fixed.Add(Xy({0, 1, 2}, {0.0, 0.5, 1.0}));
  fixed.AddHorizontalLine(10.0, kMagenta);
  fixed.AddHorizontalLine(-10.0, kCrimson);
  fixed.Save(dir / "fixed.png");
  const PngImage clipped(dir / "fixed.png");
  EXPECT_EQ(clipped.Count(Like(kMagenta)), 0);
  EXPECT_EQ(clipped.Count(Like(kCrimson)), 0);
}

TEST(LinePlot, HorizontalLineSpansTheWholeXAxis) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Xy({0, 10}, {0, 1}));
  plot.AddHorizontalLine(0.5, kMagenta);
  plot.Save(dir / "span.png");
  const PngImage image(dir / "span.png");
  const std::set<int> columns = image.ColumnsWith(Like(kMagenta));
  ASSERT_FALSE(columns.empty());
  // The line is dashed, but reaches across most of the figure.
  EXPECT_GT(*columns.rbegin() - *columns.begin(), image.width() * 3 / 4);
}

}  // namespace
}  // namespace priormap::render
