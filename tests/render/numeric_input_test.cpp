// Numbers a caller gives the figures (line widths, radii, sizes, colours, tick counts, dashes):
// each is refused where it is given, with a message naming the field and the value, or drawn
// sensibly; none hangs, fails only when the figure is saved, or is reported as something else.
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <cairo.h>
#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/line_plot.hpp>
#include <priormap/render/ticks.hpp>

// The internal panel and canvas checks have no public path that gives them bad numbers.
#include "../../src/render/canvas.hpp"
#include "../../src/render/plot_panel.hpp"
#include "testing/png_image.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::render {
namespace {

using priormap::testing::Like;
using priormap::testing::PngImage;
using priormap::testing::TempDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const Color kRed{1.0, 0.0, 0.0};

Box2 Square() {
  return Box2(Vec2(0, 0), Vec2(4, 4));
}

FigureOptions Plain() {
  return {.width_px = 200, .max_height_px = 200, .axes = false, .padding_m = 0.0};
}

// The message of the ContractError `call` throws ("" with a failure when it throws none).
template <typename Call>
std::string ContractMessage(Call call) {
  try {
    call();
  } catch (const ContractError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ContractError";
  return "";
}

// Cairo took a NaN or infinite line width and drew nothing (or, for a negative one, nothing
// either), with no word: refused where the style is given, naming the field and the value.
TEST(NumericInput, ALineWidthNotFiniteOrNegativeIsAContractErrorWhereTheStyleIsGiven) {
  Figure figure(Square(), Plain());
  const std::vector<Vec2> points = {{1, 1}, {3, 3}};
  const std::vector<double> angles = {0.0, 1.0};
  for (const double width : {kNaN, kInf, -kInf, -1.0}) {
    const LineStyle style{kRed, width, {}};
    const std::string value = ::testing::PrintToString(width);
    EXPECT_THROW(figure.Line({1, 1}, {3, 3}, style), ContractError) << value;
    EXPECT_THROW(figure.Line({1e3, 1e3}, {2e3, 1e3}, style), ContractError) << value;  // unseen
    EXPECT_THROW(figure.Polyline(points, false, style), ContractError) << value;
    EXPECT_THROW(figure.FilledPolygon(Polygon{{{1, 1}, {3, 1}, {2, 3}}}, kRed, style),
                 ContractError)
        << value;
    EXPECT_THROW(figure.CircleOutline(Circle{{2, 2}, 1}, style), ContractError) << value;
    EXPECT_THROW(figure.Arc({2, 2}, 1.0, 0.0, 1.0, style), ContractError) << value;
    EXPECT_THROW(figure.CovarianceEllipse({2, 2}, Mat2::Identity(), 1.0, style), ContractError)
        << value;
    EXPECT_THROW(figure.Ticks(points, angles, 10.0, style), ContractError) << value;
  }
  const std::string message = ContractMessage([&] {
    figure.Line({1, 1}, {3, 3}, {kRed, kNaN, {}});
  });
  EXPECT_NE(message.find("width_px"), std::string::npos) << message;
  EXPECT_NE(message.find("nan"), std::string::npos) << message;
  // 0 draws no outline, as FilledPolygon's default stroke; the figure is whole.
  figure.FilledPolygon(Polygon{{{1, 1}, {3, 1}, {2, 3}}}, kRed, {kRed, 0.0, {}});
  const TempDir dir;
  ASSERT_NO_THROW(figure.Save(dir / "widths.png"));
  const PngImage image(dir / "widths.png");
  ASSERT_TRUE(image.ok());
  EXPECT_GT(image.Count(Like(kRed)), 100);
}

TEST(NumericInput, APointRadiusNotFiniteOrNegativeIsAContractError) {
  Figure figure(Square(), Plain());
  const std::vector<Vec2> few = {{2, 2}};
  const std::vector<Vec2> many(30000, Vec2(2, 2));  // drawn as a raster layer
  for (const double radius : {kNaN, kInf, -1.0}) {
    EXPECT_THROW(figure.Points(few, kRed, radius), ContractError) << radius;
    EXPECT_THROW(figure.Points(many, kRed, radius), ContractError) << radius;
  }
  const std::string message = ContractMessage([&] { figure.Points(few, kRed, -2.5); });
  EXPECT_NE(message.find("radius_px"), std::string::npos) << message;
  EXPECT_NE(message.find("-2.5"), std::string::npos) << message;
}

// Cairo spent minutes (without end, as far as anyone waited) on a disc of 1e300 pixels. Such a
// disc covers the figure, and is drawn so.
TEST(NumericInput, APointOfAHugeRadiusCoversTheFigure) {
  const TempDir dir;
  for (const std::size_t n : {std::size_t{1}, std::size_t{30000}}) {
    Figure figure(Square(), Plain());
    figure.Points(std::vector<Vec2>(n, Vec2(2, 2)), kRed, 1e300);
    ASSERT_NO_THROW(figure.Save(dir / "disc.png"));
    const PngImage image(dir / "disc.png");
    ASSERT_TRUE(image.ok());
    // The plot, to its corners.
    for (const Vec2& corner :
         {Vec2(0.01, 0.01), Vec2(3.99, 0.01), Vec2(0.01, 3.99), Vec2(3.99, 3.99)})
      EXPECT_TRUE(Like(kRed)(image.At(figure.ToDevice(corner)))) << n << ": " << corner.transpose();
  }
}

TEST(NumericInput, ANegativeFigureSizeIsAContractErrorNamingIt) {
  FigureOptions wide = Plain();
  wide.width_px = -5;
  std::string message = ContractMessage([&] { Figure figure(Square(), wide); });
  EXPECT_NE(message.find("width_px"), std::string::npos) << message;
  EXPECT_NE(message.find("-5"), std::string::npos) << message;
  EXPECT_EQ(message.find("too large"), std::string::npos) << message;
  FigureOptions low = Plain();
  low.max_height_px = std::numeric_limits<int>::min();
  message = ContractMessage([&] { Figure figure(Square(), low); });
  EXPECT_NE(message.find("max_height_px"), std::string::npos) << message;
  // 0, like any size below the margins, still grows to leave a plot.
  wide.width_px = 0;
  EXPECT_NO_THROW(Figure(Square(), wide));

  LinePlotOptions plot;
  plot.width_px = -1;
  message = ContractMessage([&] { LinePlot line_plot(plot); });
  EXPECT_NE(message.find("width_px"), std::string::npos) << message;
  plot.width_px = 0;
  plot.height_px = -450;
  message = ContractMessage([&] { LinePlot line_plot(plot); });
  EXPECT_NE(message.find("height_px"), std::string::npos) << message;
  EXPECT_NE(message.find("-450"), std::string::npos) << message;
  plot.height_px = 0;
  EXPECT_NO_THROW(LinePlot{plot});
}

// A size that is not a number of pixels at all was reported as "too large to draw".
TEST(NumericInput, AFigureSizeThatIsNotAPositiveNumberIsNotCalledTooLarge) {
  for (const auto& [width, height] : std::vector<std::pair<double, double>>{
           {kNaN, 100}, {100, kNaN}, {-5, 100}, {100, 0}, {-kInf, 100}}) {
    const std::string message = ContractMessage([&] { detail::CheckFigureSize(width, height); });
    EXPECT_EQ(message.find("too large"), std::string::npos) << message;
    EXPECT_NE(message.find("positive, finite"), std::string::npos) << message;
  }
  const std::string nan = ContractMessage([] { detail::CheckFigureSize(kNaN, 100); });
  EXPECT_NE(nan.find("nan x 100"), std::string::npos) << nan;
  const std::string large = ContractMessage([] { detail::CheckFigureSize(40000, 100); });
  EXPECT_NE(large.find("too large"), std::string::npos) << large;
  EXPECT_NO_THROW(detail::CheckFigureSize(0.5, 1));  // whole pixels: 1 x 1
}

// Freetype fails at text of 100,000 px, which came to light only when the figure was saved, as
// an IoError "error occurred in libfreetype".
TEST(NumericInput, TextLargerThanAnyFigureIsAContractErrorWhereItIsGiven) {
  Figure figure(Square(), Plain());
  const std::string message = ContractMessage([&] { figure.Text({1, 1}, "a", 1e5); });
  EXPECT_NE(message.find("size_px"), std::string::npos) << message;
  EXPECT_NE(message.find("100000"), std::string::npos) << message;
  EXPECT_THROW(figure.Text({1, 1}, "a", 1e300), ContractError);
  figure.Text({1, 1}, "a", 40.0);
  const TempDir dir;
  EXPECT_NO_THROW(figure.Save(dir / "text.png"));
}

TEST(NumericInput, ASeriesWidthNotFiniteOrNegativeIsRefusedWhenAdded) {
  LinePlot plot;
  for (const double width : {kNaN, kInf, -1.0}) {
    Series series{.x = {0, 1}, .y = {0, 1}, .width_px = width};
    EXPECT_THROW(plot.Add(series), ContractError) << width;
    series.markers = true;
    EXPECT_THROW(plot.Add(series), ContractError) << width;
  }
  const std::string message = ContractMessage([&] {
    plot.Add({.x = {0, 1}, .y = {0, 1}, .width_px = -3.0});
  });
  EXPECT_NE(message.find("width_px"), std::string::npos) << message;
  EXPECT_NE(message.find("-3"), std::string::npos) << message;
  const TempDir dir;
  EXPECT_NO_THROW(plot.Save(dir / "plot.png"));  // nothing was added
}

// Cairo clamps colour values beyond [0, 1], but drew a NaN one as 0 (black, or nothing for a NaN
// alpha), with no word: refused where the colour is given, naming it and the value.
TEST(NumericInput, AColourNotFiniteIsAContractErrorWhereItIsGiven) {
  Figure figure(Square(), Plain());
  const std::vector<Vec2> points = {{1, 1}, {3, 3}};
  for (const Color& bad : {Color{kNaN, 0, 0}, Color{0, 0, 0, kNaN}, Color{0, kInf, 0}}) {
    const std::string value = ::testing::PrintToString(std::vector{bad.r, bad.g, bad.b, bad.a});
    EXPECT_THROW(figure.Points(points, bad), ContractError) << value;
    EXPECT_THROW(figure.Line({1, 1}, {3, 3}, {bad, 1.0, {}}), ContractError) << value;
    EXPECT_THROW(figure.FilledPolygon(Polygon{{{1, 1}, {3, 1}, {2, 3}}}, bad), ContractError)
        << value;
    EXPECT_THROW(figure.FilledCircle(Circle{{2, 2}, 1}, bad), ContractError) << value;
    EXPECT_THROW(figure.PoseMarker(Se2(2, 2, 0), bad), ContractError) << value;
    EXPECT_THROW(figure.Text({1, 1}, "a", 12.0, bad), ContractError) << value;
    EXPECT_THROW(figure.AddLegend("a", bad), ContractError) << value;
    LinePlot plot;
    EXPECT_THROW(plot.Add({.x = {0, 1}, .y = {0, 1}, .color = bad}), ContractError) << value;
    EXPECT_THROW(plot.AddHorizontalLine(0.5, bad), ContractError) << value;
  }
  const std::string message = ContractMessage([&] {
    figure.FilledCircle(Circle{{2, 2}, 1}, {0.5, kNaN, 0.5});
  });
  EXPECT_NE(message.find("fill"), std::string::npos) << message;
  EXPECT_NE(message.find("0.5, nan, 0.5, 1"), std::string::npos) << message;
  // Finite values beyond [0, 1] are the end they pass.
  figure.FilledPolygon(Polygon{{{0, 0}, {4, 0}, {4, 4}, {0, 4}}}, {2.0, -1.0, -0.5, 7.0});
  const TempDir dir;
  ASSERT_NO_THROW(figure.Save(dir / "colours.png"));
  const PngImage image(dir / "colours.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(Like(kRed)(image.At(figure.ToDevice({2, 2}))));
}

// Empty inputs and ranges were refused with messages that did not say what was given ("empty
// heat map", "NiceTicks needs lo < hi"): each names the values now.
TEST(NumericInput, EmptyInputsAndRangesAreRefusedNamingTheValues) {
  const std::string world =
      ContractMessage([] { Figure figure(Box2(Vec2(0, kNaN), Vec2(1, 1)), Plain()); });
  EXPECT_NE(world.find("[0, 1] x [nan, 1]"), std::string::npos) << world;
  Figure figure(Square(), Plain());
  const std::string cells = ContractMessage(
      [&] { figure.HeatMap(Eigen::MatrixXd(0, 3), Square(), Colormap::kViridis, 0, 1); });
  EXPECT_NE(cells.find("0 x 3"), std::string::npos) << cells;
  const std::string levels = ContractMessage(
      [&] { figure.HeatMap(Eigen::MatrixXd::Zero(2, 2), Square(), Colormap::kViridis, 2, 2); });
  EXPECT_NE(levels.find("2 and 2"), std::string::npos) << levels;
  const std::string ticks = ContractMessage([] { (void)NiceTicks(3.5, 3.5); });
  EXPECT_NE(ticks.find("[3.5, 3.5]"), std::string::npos) << ticks;
  LinePlot plot({.x_range = std::pair{1.0, 1.0}});
  const TempDir dir;
  const std::string ranges = ContractMessage([&] { plot.Save(dir / "plot.png"); });
  EXPECT_NE(ranges.find("x [1, 1]"), std::string::npos) << ranges;
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // nothing written, no temporary left
}

// Markers are discs of the series' width: one of 1e300 px hung Cairo.
TEST(NumericInput, MarkersOfAHugeWidthAreDrawnAndSaved) {
  LinePlot plot({.width_px = 300, .height_px = 200});
  plot.Add({.x = {0, 1}, .y = {0, 1}, .color = kRed, .width_px = 1e300, .markers = true});
  const TempDir dir;
  ASSERT_NO_THROW(plot.Save(dir / "markers.png"));
  const PngImage image(dir / "markers.png");
  ASSERT_TRUE(image.ok());
  EXPECT_GT(image.Count(Like(kRed)), 300 * 200 / 4);  // the plot area is covered
}

// A target of 2^31 ticks took gigabytes and then overflowed its index; one of 100,000 made as
// many ticks, more than any axis has pixels.
TEST(NumericInput, NiceTicksRefusesATargetBeyondOneTickAPixel) {
  const std::string message = ContractMessage([] { (void)NiceTicks(0.0, 1.0, 100000); });
  EXPECT_NE(message.find("target_count"), std::string::npos) << message;
  EXPECT_NE(message.find("100000"), std::string::npos) << message;
  EXPECT_THROW((void)SpacedNiceTicks(0.0, 1.0, 100000, 500.0, 10.0), ContractError);
  EXPECT_LE(NiceTicks(0.0, 1.0, kMaxFigureSidePx).size(),
            static_cast<std::size_t>(kMaxFigureSidePx) + 1);
}

// The panels of the multi-panel figures took any dashes: Cairo refused a negative or all-zero
// pattern and then drew nothing more of the figure, and drew NaN or infinite ones as it might.
// They are checked as a Figure's line style is.
class PanelDashes : public ::testing::Test {
 protected:
  PanelDashes()
      : surface_(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 400, 300)),
        cr_(cairo_create(surface_)),
        panel_(cr_, {0, 0, 400, 300}, 0.0, 1.0, 0.0, 1.0, {}) {}
  ~PanelDashes() override {
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
  }
  PanelDashes(const PanelDashes&) = delete;
  PanelDashes& operator=(const PanelDashes&) = delete;

  cairo_surface_t* surface_;
  cairo_t* cr_;
  detail::Panel panel_;
};

TEST_F(PanelDashes, DashesCairoCannotDrawAreAContractError) {
  const std::vector<Vec2> points = {{0.1, 0.1}, {0.9, 0.9}};
  for (const std::vector<double>& dashes : std::vector<std::vector<double>>{
           {-3.0}, {6.0, -1.0}, {kNaN, 4.0}, {6.0, kInf}, {0.0}, {0.0, 0.0}}) {
    const std::string pattern = ::testing::PrintToString(dashes);
    EXPECT_THROW(panel_.Polyline(points, kRed, 1.5, dashes), ContractError) << pattern;
    EXPECT_THROW(panel_.Segment(points[0], points[1], kRed, 1.5, dashes), ContractError) << pattern;
    EXPECT_THROW(panel_.LegendRow({{.label = "a", .color = kRed, .dash_px = dashes}}),
                 ContractError)
        << pattern;
  }
  const std::string message = ContractMessage([&] {
    panel_.Polyline(points, kRed, 1.5, std::vector<double>{6.0, -1.0});
  });
  EXPECT_NE(message.find("dash"), std::string::npos) << message;
  // Cairo was never given them: it still draws.
  EXPECT_EQ(cairo_status(cr_), CAIRO_STATUS_SUCCESS) << cairo_status_to_string(cairo_status(cr_));
  panel_.Polyline(points, kRed, 1.5, std::vector<double>{6.0, 4.0});
  panel_.LegendRow({{.label = "a", .color = kRed, .dash_px = {0.0, 6.0}}});
  EXPECT_EQ(cairo_status(cr_), CAIRO_STATUS_SUCCESS) << cairo_status_to_string(cairo_status(cr_));
}

TEST_F(PanelDashes, ALineWidthNotFiniteOrNegativeIsAContractError) {
  const std::vector<Vec2> points = {{0.1, 0.1}, {0.9, 0.9}};
  for (const double width : {kNaN, kInf, -1.0}) {
    EXPECT_THROW(panel_.Polyline(points, kRed, width), ContractError) << width;
    EXPECT_THROW(panel_.LegendRow({{.label = "a", .color = kRed, .width_px = width}}),
                 ContractError)
        << width;
  }
  EXPECT_EQ(cairo_status(cr_), CAIRO_STATUS_SUCCESS) << cairo_status_to_string(cairo_status(cr_));
}

}  // namespace
}  // namespace priormap::render
