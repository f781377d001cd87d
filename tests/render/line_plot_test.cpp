#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/line_plot.hpp>

#include "testing/png_image.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::render {
namespace {

namespace fs = std::filesystem;
using priormap::testing::HasTemporaryFile;
using priormap::testing::Like;
using priormap::testing::PixelPredicate;
using priormap::testing::PngImage;
using priormap::testing::ReadAll;
using priormap::testing::Rgba;
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

// The plot's frame as the image shows it: the black rectangle of width 1 around the data area,
// the only dark lines that run across most of the figure (text is short, the grid light grey).
// Its edges are in device coordinates (pixel (i, j) covers [i, i + 1] x [j, j + 1]), found from
// the image alone, so that the tests below check the data's placement against the frame without
// repeating the plot's layout.
struct Frame {
  double left = 0.0, right = 0.0, top = 0.0, bottom = 0.0;
  // Where a data point falls for the axis ranges [x_lo, x_hi] x [y_lo, y_hi] (y up).
  [[nodiscard]] Vec2 ToDevice(double x, double y, std::pair<double, double> x_range,
                              std::pair<double, double> y_range) const {
    return {left + (x - x_range.first) / (x_range.second - x_range.first) * (right - left),
            bottom - (y - y_range.first) / (y_range.second - y_range.first) * (bottom - top)};
  }
};

bool Dark(const Rgba& p) {
  return p.r <= 160 && p.r == p.g && p.g == p.b;
}

// The mean position (pixel centres, weighted by `darkness`) of those of `lines` (the rows or
// columns dark across most of the image) within two pixels of `first`: one edge of the frame.
double LineCentre(const std::vector<double>& darkness, const std::vector<int>& lines, int first) {
  double sum = 0.0, weight = 0.0;
  for (int i : lines) {
    if (std::abs(i - first) > 2) continue;
    sum += (i + 0.5) * darkness[static_cast<std::size_t>(i)];
    weight += darkness[static_cast<std::size_t>(i)];
  }
  return sum / weight;
}

std::optional<Frame> FindFrame(const PngImage& image) {
  const int w = image.width(), h = image.height();
  std::vector<int> rows, columns;
  std::vector<double> row_darkness(static_cast<std::size_t>(h)),
      column_darkness(static_cast<std::size_t>(w));
  std::vector<int> row_count(static_cast<std::size_t>(h)),
      column_count(static_cast<std::size_t>(w));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Rgba p = image.At(x, y);
      if (!Dark(p)) continue;
      ++row_count[static_cast<std::size_t>(y)];
      ++column_count[static_cast<std::size_t>(x)];
      row_darkness[static_cast<std::size_t>(y)] += 255 - p.r;
      column_darkness[static_cast<std::size_t>(x)] += 255 - p.r;
    }
  }
  for (int y = 0; y < h; ++y)
    if (row_count[static_cast<std::size_t>(y)] > w / 2) rows.push_back(y);
  for (int x = 0; x < w; ++x)
    if (column_count[static_cast<std::size_t>(x)] > h / 2) columns.push_back(x);
  if (rows.size() < 2 || columns.size() < 2 || rows.back() - rows.front() < 10 ||
      columns.back() - columns.front() < 10)
    return std::nullopt;
  return Frame{LineCentre(column_darkness, columns, columns.front()),
               LineCentre(column_darkness, columns, columns.back()),
               LineCentre(row_darkness, rows, rows.front()),
               LineCentre(row_darkness, rows, rows.back())};
}

// The mean row (pixel centres) of the pixels of column `x` that satisfy `predicate`; nullopt
// when there is none.
std::optional<double> MeanRow(const PngImage& image, int x, const PixelPredicate& predicate) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < image.height(); ++y) {
    if (predicate(image.At(x, y))) {
      sum += y + 0.5;
      ++n;
    }
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

// The rows that hold a pixel satisfying `predicate`.
std::set<int> RowsWith(const PngImage& image, const PixelPredicate& predicate) {
  std::set<int> rows;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (predicate(image.At(x, y))) rows.insert(y);
  return rows;
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
  // The PNG shows the plot, not just a canvas of the right size: the frame, most of the figure,
  // and the legend's swatch of the labelled series (palette colour 0, a horizontal bar) in the
  // frame's top-right corner.
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  EXPECT_GT(frame->right - frame->left, 0.7 * 640);
  EXPECT_GT(frame->bottom - frame->top, 0.6 * 360);
  int longest_swatch_run = 0;
  const PixelPredicate swatch = Like(palette::Categorical(0));
  for (int y = static_cast<int>(frame->top); y < static_cast<int>(frame->top) + 40; ++y) {
    int run = 0;
    for (int x = static_cast<int>(frame->right) - 200; x < static_cast<int>(frame->right); ++x) {
      run = swatch(image.At(x, y)) ? run + 1 : 0;
      longest_swatch_run = std::max(longest_swatch_run, run);
    }
  }
  EXPECT_GE(longest_swatch_run, 18);

  const std::string svg = ReadAll(dir / "p.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("width=\"640"), std::string::npos);
  EXPECT_NE(svg.find("height=\"360"), std::string::npos);

  const std::string pdf = ReadAll(dir / "p.pdf");
  EXPECT_TRUE(pdf.starts_with("%PDF"));
  EXPECT_NE(pdf.find("/MediaBox [ 0 0 640 360 ]"), std::string::npos);
  EXPECT_FALSE(HasTemporaryFile(dir.path()));
}

// A line plot has its size from the start: refused when made, not when saved.
TEST(LinePlot, ASizeBeyondTheLimitsIsRefusedWhenMade) {
  LinePlotOptions options;
  options.width_px = 40000;
  EXPECT_THROW(LinePlot{options}, ContractError);
  options.width_px = 9000;
  options.height_px = 9000;
  EXPECT_THROW(LinePlot{options}, ContractError);
  options.height_px = 450;
  EXPECT_NO_THROW(LinePlot{options});
}

TEST(LinePlot, SeriesWithMismatchedSizesIsAContractErrorAndWritesNothing) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Xy({0, 1, 2}, {0, 1}));
  EXPECT_THROW(plot.Save(dir / "bad.png"), ContractError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// A dash pattern Cairo cannot draw (a negative length, none but zeros, NaN or infinity) failed
// only when saved, or not at all: refused when the series is added.
TEST(LinePlot, ASeriesWithADashPatternCairoCannotDrawIsRefusedWhenAdded) {
  const double inf = std::numeric_limits<double>::infinity();
  LinePlot plot;
  for (const std::vector<double>& dashes : std::vector<std::vector<double>>{
           {-3.0}, {6.0, -1.0}, {std::nan(""), 4.0}, {6.0, inf}, {0.0}, {0.0, 0.0}}) {
    Series series = Xy({0, 1}, {0, 1});
    series.dash_px = dashes;
    EXPECT_THROW(plot.Add(series), ContractError) << ::testing::PrintToString(dashes);
  }
  Series dashed = Xy({0, 1}, {0, 1});
  dashed.dash_px = {6.0, 4.0};
  plot.Add(dashed);
  const TempDir dir;
  EXPECT_NO_THROW(plot.Save(dir / "dashed.png"));
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
  // An empty frame: inside it only white and the light grey grid, nothing in colour anywhere,
  // and the title's text above the frame, centred on it.
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  int inside = 0, blank = 0, coloured = 0;
  double title_x = 0.0;
  int title_pixels = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const Rgba p = image.At(x, y);
      coloured += std::max({p.r, p.g, p.b}) - std::min({p.r, p.g, p.b}) > 10 ? 1 : 0;
      if (x > frame->left + 1 && x + 1 < frame->right - 1 && y > frame->top + 1 &&
          y + 1 < frame->bottom - 1) {
        ++inside;
        blank += p.r >= 200 && p.r == p.g && p.g == p.b ? 1 : 0;
      }
      if (y + 1 < frame->top && Dark(p)) {
        title_x += x + 0.5;
        ++title_pixels;
      }
    }
  }
  EXPECT_EQ(blank, inside);
  EXPECT_EQ(coloured, 0);
  ASSERT_GT(title_pixels, 20);
  EXPECT_NEAR(title_x / title_pixels, (frame->left + frame->right) / 2, 10.0);
}

// An all-NaN series draws nothing; a series of one repeated point draws a dot (the round cap of
// a segment of no length) in the middle of the frame, its ranges padded evenly around it.
TEST(LinePlot, AllNanOrConstantSeriesStillSave) {
  const TempDir dir;
  LinePlot all_nan;
  all_nan.Add(Line({0, 1, 2}, {kNaN, kNaN, kNaN}, kCrimson));
  EXPECT_NO_THROW(all_nan.Save(dir / "nan.png"));
  const PngImage nan_image(dir / "nan.png");
  ASSERT_TRUE(nan_image.ok());
  EXPECT_TRUE(FindFrame(nan_image).has_value());
  EXPECT_EQ(nan_image.Count(Like(kCrimson)), 0);

  LinePlot constant;
  constant.Add(Line({5, 5}, {-2, -2}, kCrimson));
  EXPECT_NO_THROW(constant.Save(dir / "constant.png"));
  const PngImage image(dir / "constant.png");
  ASSERT_TRUE(image.ok());
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  const Vec2 centre((frame->left + frame->right) / 2, (frame->top + frame->bottom) / 2);
  EXPECT_TRUE(Like(kCrimson)(image.At(centre))) << priormap::testing::Describe(image.At(centre));
  // The dot and nothing else: a disc of diameter 4 covers a few pixels, all next to the centre.
  const int dot = image.Count(Like(kCrimson));
  EXPECT_GT(dot, 0);
  EXPECT_LT(dot, 25);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (Like(kCrimson)(image.At(x, y))) {
        EXPECT_LT(std::abs(x + 0.5 - centre.x()), 3.0) << x << " " << y;
        EXPECT_LT(std::abs(y + 0.5 - centre.y()), 3.0) << x << " " << y;
      }
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

// A bound that diverged to infinity cannot set the axis, and is left out; the data are drawn.
TEST(LinePlot, AnInfiniteHorizontalLineIsLeftOut) {
  const TempDir dir;
  LinePlot plot;
  plot.Add(Line({0, 1, 2}, {0, 2, 1}, kCrimson));
  plot.AddHorizontalLine(std::numeric_limits<double>::infinity(), kMagenta, "3 sigma");
  plot.Save(dir / "infinite.png");
  const PngImage image(dir / "infinite.png");
  ASSERT_TRUE(image.ok());
  EXPECT_GT(image.Count(Like(kCrimson)), 100);
}

// Data from one end of the doubles to the other: the padded range overflowed to infinity.
TEST(LinePlot, DataSpanningAllDoublesAreDrawn) {
  const TempDir dir;
  const double big = std::numeric_limits<double>::max();
  LinePlot plot;
  plot.Add(Line({0, 1, 2}, {-big, 0, big}, kCrimson));
  plot.Save(dir / "span.png");
  const PngImage image(dir / "span.png");
  ASSERT_TRUE(image.ok());
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  // The middle point, (1, 0), is at the centre of the plot.
  const Vec2 centre((frame->left + frame->right) / 2, (frame->top + frame->bottom) / 2);
  EXPECT_TRUE(Like(kCrimson)(image.At(centre))) << priormap::testing::Describe(image.At(centre));
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

// Series 0 rises from (0, 0) to (1, 1), series 1 falls from (0, 1) to (1, 0): each in the palette
// colour of its index, and each where its data are (x to the right, y up) against the frame.
TEST(LinePlot, SeriesWithoutColourTakesThePaletteColourOfItsIndex) {
  const TempDir dir;
  LinePlotOptions options;
  options.x_range = std::pair{-0.25, 1.25};
  options.y_range = std::pair{-0.5, 1.5};
  LinePlot plot(options);
  plot.Add(Xy({0, 1}, {0, 1}, 4.0));
  plot.Add(Xy({0, 1}, {1, 0}, 4.0));
  plot.Save(dir / "palette.png");
  const PngImage image(dir / "palette.png");
  ASSERT_TRUE(image.ok());
  EXPECT_GT(image.Count(Like(palette::Categorical(0))), 50);
  EXPECT_GT(image.Count(Like(palette::Categorical(1))), 50);
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  for (const double x : {0.2, 0.35, 0.65, 0.8}) {
    const Vec2 rising = frame->ToDevice(x, x, *options.x_range, *options.y_range);
    const Vec2 falling = frame->ToDevice(x, 1.0 - x, *options.x_range, *options.y_range);
    const int column = static_cast<int>(std::floor(rising.x()));
    const std::optional<double> row0 = MeanRow(image, column, Like(palette::Categorical(0)));
    const std::optional<double> row1 = MeanRow(image, column, Like(palette::Categorical(1)));
    ASSERT_TRUE(row0.has_value()) << "x = " << x;
    ASSERT_TRUE(row1.has_value()) << "x = " << x;
    EXPECT_NEAR(*row0, rising.y(), 1.5) << "series 0 at x = " << x;
    EXPECT_NEAR(*row1, falling.y(), 1.5) << "series 1 at x = " << x;
  }
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
  // y = 10 runs along the top of the frame and y = -10 along its bottom (the range is theirs and
  // a little more), each on one row; the data (palette colour 0, y in [0, 1]) in the middle.
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  const double height = frame->bottom - frame->top;
  const std::set<int> top_rows = RowsWith(image, Like(kMagenta));
  const std::set<int> bottom_rows = RowsWith(image, Like(kCrimson));
  ASSERT_FALSE(top_rows.empty());
  ASSERT_FALSE(bottom_rows.empty());
  EXPECT_LE(*top_rows.rbegin() - *top_rows.begin(), 1);
  EXPECT_LE(*bottom_rows.rbegin() - *bottom_rows.begin(), 1);
  EXPECT_GT(*top_rows.begin(), frame->top);
  EXPECT_LT(*top_rows.rbegin(), frame->top + 0.1 * height);
  EXPECT_LT(*bottom_rows.rbegin() + 1, frame->bottom);
  EXPECT_GT(*bottom_rows.begin(), frame->bottom - 0.1 * height);
  const int middle = static_cast<int>((frame->left + frame->right) / 2);
  const std::optional<double> data_row =
      MeanRow(image, middle, [](const Rgba& p) { return p.b - p.r > 60; });  // palette blue
  ASSERT_TRUE(data_row.has_value());
  EXPECT_NEAR(*data_row, (frame->top + frame->bottom) / 2, 0.1 * height);

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

// The x labels are centred on their ticks, and the last tick is at the plot's right end when the
// data end on a round number: "1000000" (48 px) was cut by the 20 px margin. The margin grows:
// the label is whole, centred on the frame's right edge.
TEST(LinePlot, TheLastXTickLabelIsWholeAndCentredOnItsTick) {
  const TempDir dir;
  for (const double end : {1e6, 1e7, -1e6}) {
    LinePlot plot;
    plot.Add(Xy({end < 0 ? end : 0.0, end < 0 ? 0.0 : end}, {0, 1}));
    plot.Save(dir / "labels.png");
    const PngImage image(dir / "labels.png");
    ASSERT_TRUE(image.ok());
    const std::optional<Frame> frame = FindFrame(image);
    ASSERT_TRUE(frame.has_value());
    const int row = static_cast<int>(frame->bottom);
    const std::vector<std::pair<int, int>> labels = image.InkRuns(row + 3, row + 18, 4);
    ASSERT_GE(labels.size(), 3u) << end;
    for (const auto& [first, last] : {labels.front(), labels.back()}) {
      EXPECT_GT(first, 1) << end;
      EXPECT_LT(last, image.width() - 2) << end << ": the label runs to the figure's edge";
    }
    // The label at the end of the data is whole, centred on its tick at the frame's edge.
    const auto [first, last] = end < 0 ? labels.front() : labels.back();
    const double tick = end < 0 ? frame->left : frame->right;
    EXPECT_NEAR((first + last + 1) / 2.0, tick, 2.0) << end;
    EXPECT_GE(last + 1 - first, TextWidth(end == 1e7 ? "10000000" : "1000000", 11.0) - 3.0) << end;
  }
  // Labels that fit leave the layout as it was: the frame ends 20 px from the edge.
  LinePlot plain;
  plain.Add(Xy({0, 10}, {0, 1}));
  plain.Save(dir / "plain.png");
  const std::optional<Frame> frame = FindFrame(PngImage(dir / "plain.png"));
  ASSERT_TRUE(frame.has_value());
  EXPECT_NEAR(frame->right, 800 - 20, 1.0);
  EXPECT_NEAR(frame->left, 72, 1.0);
}

// The y label (rotated, 16 px from the edge) and the y tick labels, drawn the same with and
// without it: the pixels that differ are the y label's, and no tick label's ink may be near them.
// Values in the millions had labels that ran into it; the left margin grows.
TEST(LinePlot, WideYTickLabelsKeepClearOfTheYLabel) {
  const TempDir dir;
  const auto draw = [&](const std::string& y_label, double width, const std::string& name) {
    LinePlotOptions options = Size(static_cast<int>(width), 450);
    options.y_label = y_label;
    LinePlot plot(options);
    plot.Add(Xy({0, 1}, {-1e6, 1e6}));
    plot.Save(dir / name);
    return PngImage(dir / name);
  };
  for (const double width : {800.0, 200.0}) {
    const PngImage without = draw("", width, "without.png");
    const PngImage with = draw("range of the beam, measured (m)", width, "with.png");
    ASSERT_TRUE(without.ok() && with.ok());
    const auto dark = [](const Rgba& p) { return p.r < 160 && p.g < 160 && p.b < 160; };
    int label_pixels = 0, touching = 0;
    for (int y = 0; y < with.height(); ++y) {
      for (int x = 0; x < with.width(); ++x) {
        if (Near(with.At(x, y), without.At(x, y), 8)) continue;
        ++label_pixels;
        for (int v = std::max(y - 2, 0); v <= std::min(y + 2, with.height() - 1); ++v)
          for (int u = std::max(x - 2, 0); u <= std::min(x + 2, with.width() - 1); ++u)
            touching += dark(without.At(u, v)) ? 1 : 0;
      }
    }
    EXPECT_GT(label_pixels, 100) << width;
    EXPECT_EQ(touching, 0) << width;
  }
}

// The smallest plot (200 x 150) put six x labels of "100000" where two fit: they ran into each
// other. Ticks are no closer than their labels need, along both axes.
TEST(LinePlot, TickLabelsOfASmallPlotDoNotRunIntoEachOther) {
  const TempDir dir;
  LinePlot plot(Size(200, 150));
  plot.Add(Xy({0, 1e5}, {0, 1}));
  plot.Save(dir / "small.png");
  const PngImage image(dir / "small.png");
  ASSERT_TRUE(image.ok());
  const std::optional<Frame> frame = FindFrame(image);
  ASSERT_TRUE(frame.has_value());
  // Along the x labels' row: separate labels, none wider than the widest.
  const int row = static_cast<int>(frame->bottom);
  const std::vector<std::pair<int, int>> xs = image.InkRuns(row + 3, row + 18, 3);
  ASSERT_GE(xs.size(), 2u);
  for (const auto& [first, last] : xs)
    EXPECT_LE(last + 1 - first, TextWidth("100000", 11.0)) << first;
  // Down the y labels' column: separate labels, each a line of digits high.
  std::vector<std::pair<int, int>> ys;
  int blank = 2;
  for (int y = static_cast<int>(frame->top) - 8; y < static_cast<int>(frame->bottom) + 8; ++y) {
    bool ink = false;
    for (int x = static_cast<int>(frame->left) - 40; x < static_cast<int>(frame->left) - 3; ++x) {
      const Rgba p = image.At(x, y);
      ink = ink || (p.r < 128 && p.g < 128 && p.b < 128);
    }
    if (!ink) {
      ++blank;
      continue;
    }
    if (blank >= 2) {
      ys.emplace_back(y, y);
    } else {
      ys.back().second = y;
    }
    blank = 0;
  }
  ASSERT_GE(ys.size(), 2u);
  for (const auto& [first, last] : ys) EXPECT_LE(last + 1 - first, 10) << first;
}

// Cairo's fixed-point coordinates wrap beyond 8.4 million pixels: a line to a point far beyond
// an explicit range (1e5, 70 million pixels away) stopped in the middle of the plot, or ran
// elsewhere. It is clipped where it leaves the plot; far markers are not drawn.
TEST(LinePlot, DataFarBeyondAnExplicitRangeIsClippedWhereItLeavesThePlot) {
  const TempDir dir;
  for (const double far : {1e3, 1e5, 1e7, 1e12, 1e300}) {
    LinePlotOptions options;
    options.x_range = std::pair{0.0, 1.0};
    options.y_range = std::pair{0.0, 1.0};
    LinePlot plot(options);
    plot.Add(Line({0.25, far}, {0.25, far}, kCrimson));  // the diagonal, out at the top right
    Series dots = Line({far, 0.5, -far}, {0.5, far, 0.5}, kMagenta);
    dots.markers = true;
    plot.Add(dots);
    plot.Save(dir / "far.png");
    const PngImage image(dir / "far.png");
    ASSERT_TRUE(image.ok());
    const std::optional<Frame> frame = FindFrame(image);
    ASSERT_TRUE(frame.has_value());
    const std::set<int> columns = image.ColumnsWith(Like(kCrimson));
    ASSERT_FALSE(columns.empty()) << far;
    EXPECT_NEAR(*columns.begin(), frame->left + 0.25 * (frame->right - frame->left), 3.0) << far;
    EXPECT_GT(*columns.rbegin(), frame->right - 4.0) << far;
    // On the diagonal all the way.
    for (const double t : {0.3, 0.5, 0.7, 0.9}) {
      const Vec2 d = frame->ToDevice(t, t, {0.0, 1.0}, {0.0, 1.0});
      const std::optional<double> row = MeanRow(image, static_cast<int>(d.x()), Like(kCrimson));
      ASSERT_TRUE(row.has_value()) << far << " at " << t;
      EXPECT_NEAR(*row, d.y(), 2.0) << far << " at " << t;
    }
    EXPECT_EQ(image.Count(Like(kMagenta)), 0) << far;
  }
}

}  // namespace
}  // namespace priormap::render
