#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <cairo/cairo.h>
#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/render/color.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/figure_size.hpp>
#include <priormap/render/scene_drawing.hpp>

#include "testing/png_image.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::render {
namespace {

namespace fs = std::filesystem;
using priormap::testing::ColorNear;
using priormap::testing::FilesIn;
using priormap::testing::HasTemporaryFile;
using priormap::testing::Like;
using priormap::testing::Near;
using priormap::testing::PixelPredicate;
using priormap::testing::PngImage;
using priormap::testing::ReadAll;
using priormap::testing::Rgba;
using priormap::testing::TempDir;
using priormap::testing::ToRgba;
using priormap::testing::WriteAll;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const Rgba kWhite{255, 255, 255, 255};

Box2 World(double x0, double y0, double x1, double y1) {
  return Box2(Vec2(x0, y0), Vec2(x1, y1));
}

FigureOptions Options(int width, int max_height = 800) {
  FigureOptions options;
  options.width_px = width;
  options.max_height_px = max_height;
  return options;
}

// No axes and no padding: the world fills the figure but for small margins.
FigureOptions Plain(int width = 400) {
  FigureOptions options = Options(width, 1000);
  options.axes = false;
  options.padding_m = 0.0;
  return options;
}

// `color` drawn over white with alpha `alpha`, as Cairo blends it (to within rounding).
Rgba OverWhite(const Color& color, double alpha) {
  return ToRgba(Color{alpha * color.r + (1.0 - alpha), alpha * color.g + (1.0 - alpha),
                      alpha * color.b + (1.0 - alpha)});
}

bool InImage(const PngImage& image, const Vec2& device) {
  return device.x() >= 0.0 && device.y() >= 0.0 && device.x() < image.width() &&
         device.y() < image.height();
}

// Whether a pixel within `radius` pixels (per axis) of the device point satisfies `predicate`.
bool AnyNear(const PngImage& image, const Vec2& device, int radius,
             const PixelPredicate& predicate) {
  const int cx = static_cast<int>(std::floor(device.x()));
  const int cy = static_cast<int>(std::floor(device.y()));
  for (int y = cy - radius; y <= cy + radius; ++y)
    for (int x = cx - radius; x <= cx + radius; ++x)
      if (x >= 0 && y >= 0 && x < image.width() && y < image.height() && predicate(image.At(x, y)))
        return true;
  return false;
}

// Pixels that are not white.
int Ink(const PngImage& image) {
  return image.Count([](const Rgba& p) { return p.r + p.g + p.b < 3 * 255 - 30; });
}

// --- Files -------------------------------------------------------------------------------------

TEST(Figure, SavesPngSvgAndPdfWithTheirSignatures) {
  const TempDir dir;
  FigureOptions options;
  options.title = "formats";
  Figure figure(World(0, 0, 4, 3), options);
  figure.Line({0, 0}, {4, 3}, {});
  figure.Save(dir / "f.png");
  figure.Save(dir / "f.svg");
  figure.Save(dir / "f.pdf");
  const std::string png = ReadAll(dir / "f.png");
  const std::string svg = ReadAll(dir / "f.svg");
  const std::string pdf = ReadAll(dir / "f.pdf");
  EXPECT_TRUE(png.starts_with("\x89PNG\r\n\x1a\n"));
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_TRUE(pdf.starts_with("%PDF"));
  EXPECT_FALSE(HasTemporaryFile(dir.path()));
}

TEST(Figure, PngHasTheFiguresPixelSize) {
  const TempDir dir;
  for (const Box2& world : {World(0, 0, 10, 5), World(-1, -8, 1, 8), World(0, 0, 3, 3)}) {
    Figure figure(world, Options(500, 420));
    EXPECT_EQ(figure.width_px(), 500);
    EXPECT_LE(figure.height_px(), 420);
    figure.Save(dir / "size.png");
    const PngImage image(dir / "size.png");
    ASSERT_TRUE(image.ok());
    EXPECT_EQ(image.width(), figure.width_px());
    EXPECT_EQ(image.height(), figure.height_px());
  }
}

TEST(Figure, HeightFollowsTheWorldsAspectRatio) {
  const Figure wide(World(0, 0, 20, 2), Plain(600));
  const Figure square(World(0, 0, 5, 5), Plain(600));
  EXPECT_LT(wide.height_px(), square.height_px());
  // Without axes the margins are small: a square world gives a nearly square figure.
  EXPECT_NEAR(square.height_px(), square.width_px(), 40);
}

TEST(Figure, SavingOverAnExistingFileReplacesIt) {
  const TempDir dir;
  WriteAll(dir / "old.svg", "not a figure");
  Figure figure(World(0, 0, 1, 1));
  figure.Save(dir / "old.svg");
  EXPECT_NE(ReadAll(dir / "old.svg").find("<svg"), std::string::npos);
  EXPECT_EQ(FilesIn(dir.path()).size(), 1u);
}

TEST(Figure, UnsupportedExtensionThrowsIoErrorAndWritesNothing) {
  const TempDir dir;
  const Figure figure(World(0, 0, 1, 1));
  EXPECT_THROW(figure.Save(dir / "figure.bmp"), IoError);
  EXPECT_THROW(figure.Save(dir / "figure"), IoError);
  EXPECT_THROW(figure.Save(dir / "figure.PNG.txt"), IoError);
  EXPECT_TRUE(FilesIn(dir.path()).empty());
}

TEST(Figure, SavingIntoAMissingDirectoryThrowsIoError) {
  const TempDir dir;
  const Figure figure(World(0, 0, 1, 1));
  for (const char* name : {"f.png", "f.svg", "f.pdf"}) {
    EXPECT_THROW(figure.Save(dir / "missing" / name), IoError) << name;
  }
  EXPECT_TRUE(FilesIn(dir.path()).empty());
}

// The write succeeds into the temporary file, then renaming it over a directory fails.
TEST(Figure, FailedSaveLeavesNoTemporaryFileAndKeepsTheTarget) {
  const TempDir dir;
  const Figure figure(World(0, 0, 1, 1));
  for (const char* name : {"f.png", "f.svg", "f.pdf"}) {
    fs::create_directory(dir / name);
    WriteAll(dir / name / "keep.txt", "kept");
    EXPECT_THROW(figure.Save(dir / name), IoError) << name;
    EXPECT_FALSE(HasTemporaryFile(dir.path())) << name;
    EXPECT_EQ(ReadAll(dir / name / "keep.txt"), "kept");
  }
  EXPECT_EQ(FilesIn(dir.path()).size(), 3u);
}

TEST(Figure, SupportedFigurePathsArePngSvgAndPdf) {
  EXPECT_TRUE(IsSupportedFigurePath("a/b.png"));
  EXPECT_TRUE(IsSupportedFigurePath("b.svg"));
  EXPECT_TRUE(IsSupportedFigurePath("b.pdf"));
  EXPECT_FALSE(IsSupportedFigurePath("b.jpg"));
  EXPECT_FALSE(IsSupportedFigurePath("b"));
  EXPECT_FALSE(IsSupportedFigurePath("png"));
}

// --- Size --------------------------------------------------------------------------------------

// Cairo makes no image over 32767 px a side: such a figure was drawn in full and failed only when
// saved, after allocating (30,000 x 30,000 px: 3.6 GB). It is refused when made, saying why.
TEST(Figure, ASideBeyondCairosImagesIsRefusedWhenTheFigureIsMade) {
  try {
    const Figure figure(World(0, 0, 1, 1), Options(30000, 30000));
    ADD_FAILURE() << "made a figure of " << figure.width_px() << " x " << figure.height_px();
  } catch (const ContractError& e) {
    EXPECT_NE(std::string(e.what()).find("30000 x 30000 px"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("32767"), std::string::npos) << e.what();
  }
  // One side too long is enough, whatever the total.
  EXPECT_THROW(Figure(World(0, 0, 1000, 1), Options(32768, 100)), ContractError);
  EXPECT_NO_THROW(Figure(World(0, 0, 1000, 1), Options(32767, 100)));
}

// 20,000 x 20,000 px is within Cairo's sides but 1.6 GB of image: beyond the 8192 x 8192 px cap.
TEST(Figure, MorePixelsThanTheCapAreRefusedWhenTheFigureIsMade) {
  try {
    const Figure figure(World(0, 0, 1, 1), Options(20000, 20000));
    ADD_FAILURE() << "made a figure of " << figure.width_px() << " x " << figure.height_px();
  } catch (const ContractError& e) {
    EXPECT_NE(std::string(e.what()).find("20000 x 20000 px"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(kMaxFigurePixels)), std::string::npos)
        << e.what();
  }
  // The command line's largest (plot --width 8000 of a square world) fits, as does the cap.
  const Figure largest(World(0, 0, 1, 1), Options(8000, 8000));
  EXPECT_LE(std::int64_t{largest.width_px()} * largest.height_px(), kMaxFigurePixels);
  EXPECT_NO_THROW(Figure(World(0, 0, 1, 1), Options(8192, 8192)));
  EXPECT_THROW(Figure(World(0, 0, 1, 1), Options(8193, 8193)), ContractError);
}

TEST(FigureSizeFits, HoldsUpToEitherLimit) {
  EXPECT_TRUE(FigureSizeFits(800, 600));
  EXPECT_TRUE(FigureSizeFits(kMaxFigureSidePx, 2048));
  EXPECT_TRUE(FigureSizeFits(8192, 8192));
  EXPECT_TRUE(FigureSizeFits(8191.5, 8192));  // whole pixels: 8192
  EXPECT_FALSE(FigureSizeFits(8192.5, 8192));
  EXPECT_FALSE(FigureSizeFits(kMaxFigureSidePx + 1, 1));
  EXPECT_FALSE(FigureSizeFits(1, kMaxFigureSidePx + 1));
  EXPECT_FALSE(FigureSizeFits(0, 100));
  EXPECT_FALSE(FigureSizeFits(-5, 100));
  EXPECT_FALSE(FigureSizeFits(kNaN, 100));
  EXPECT_FALSE(FigureSizeFits(100, std::numeric_limits<double>::infinity()));
}

// --- Geometry ----------------------------------------------------------------------------------

TEST(Figure, WorldIsDrawnWithEqualAspectAndYUp) {
  const Figure figure(World(-2, 1, 8, 6), Options(700, 700));
  const Vec2 lower_left = figure.ToDevice({-2, 1});
  const Vec2 lower_right = figure.ToDevice({8, 1});
  const Vec2 upper_left = figure.ToDevice({-2, 6});
  const Vec2 upper_right = figure.ToDevice({8, 6});
  // x to the right, y up (device y grows downwards).
  EXPECT_GT(lower_right.x(), lower_left.x());
  EXPECT_LT(upper_left.y(), lower_left.y());
  EXPECT_DOUBLE_EQ(lower_left.x(), upper_left.x());
  EXPECT_DOUBLE_EQ(lower_left.y(), lower_right.y());
  // The same number of pixels per metre along both axes.
  const double x_scale = (lower_right.x() - lower_left.x()) / 10.0;
  const double y_scale = (lower_left.y() - upper_left.y()) / 5.0;
  EXPECT_GT(x_scale, 0.0);
  EXPECT_NEAR(x_scale, y_scale, 1e-9 * x_scale);
  // The world lies inside the figure.
  for (const Vec2& corner : {lower_left, lower_right, upper_left, upper_right}) {
    EXPECT_GE(corner.x(), 0.0);
    EXPECT_LE(corner.x(), figure.width_px());
    EXPECT_GE(corner.y(), 0.0);
    EXPECT_LE(corner.y(), figure.height_px());
  }
}

TEST(Figure, WorldUpIsImageUp) {
  const TempDir dir;
  Figure figure(World(0, 0, 4, 4), Plain());
  const Color red{1.0, 0.0, 0.0};
  figure.FilledPolygon(Polygon{{{0.0, 2.0}, {4.0, 2.0}, {4.0, 4.0}, {0.0, 4.0}}}, red);  // y > 2
  figure.Save(dir / "up.png");
  const PngImage image(dir / "up.png");
  ASSERT_TRUE(image.ok());
  const Vec2 top = figure.ToDevice({2.0, 3.5});
  const Vec2 bottom = figure.ToDevice({2.0, 0.5});
  EXPECT_LT(top.y(), bottom.y());
  EXPECT_TRUE(ColorNear(image.At(top), ToRgba(red)));
  EXPECT_TRUE(ColorNear(image.At(bottom), kWhite));
}

// --- Pixels ------------------------------------------------------------------------------------

TEST(Figure, FilledPolygonInteriorHasTheFillColour) {
  const TempDir dir;
  Figure figure(World(0, 0, 10, 6), Options(500));
  const Color fill{0.8, 0.1, 0.3};
  figure.FilledPolygon(Polygon{{{2.0, 1.0}, {6.0, 1.0}, {4.0, 5.0}}}, fill,
                       {palette::kBlack, 2.0, {}});
  figure.Save(dir / "polygon.png");
  const PngImage image(dir / "polygon.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({4.0, 2.5})), ToRgba(fill)));
  // Outside the triangle (but inside the world) the background stays white.
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({8.0, 4.0})), kWhite));
  // The outline is drawn on the edge.
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({4.0, 1.0})), (Rgba{0, 0, 0, 255})));
}

TEST(Figure, TranslucentFillIsBlendedOverWhite) {
  const TempDir dir;
  Figure figure(World(0, 0, 2, 2), Plain(200));
  figure.FilledPolygon(Polygon{{{0.0, 0.0}, {2.0, 0.0}, {2.0, 2.0}, {0.0, 2.0}}},
                       Color{0.0, 0.0, 1.0, 0.5});
  figure.Save(dir / "alpha.png");
  const PngImage image(dir / "alpha.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.0, 1.0})), Rgba{128, 128, 255, 255}, 2));
}

TEST(Figure, HeatMapCellHasItsColormapColour) {
  const TempDir dir;
  Figure figure(World(0, 0, 6, 4), Plain());
  Eigen::MatrixXd values(2, 3);
  values << 0.0, 1.0, 2.0,  //
      3.0, 4.0, 5.0;
  figure.HeatMap(values, World(0, 0, 6, 4), Colormap::kViridis, 0.0, 5.0);
  figure.Save(dir / "heat.png");
  const PngImage image(dir / "heat.png");
  ASSERT_TRUE(image.ok());
  for (int iy = 0; iy < 2; ++iy) {
    for (int ix = 0; ix < 3; ++ix) {
      const Vec2 centre(2.0 * ix + 1.0, 2.0 * iy + 1.0);
      const Color expected = MapColor(Colormap::kViridis, values(iy, ix) / 5.0);
      EXPECT_TRUE(ColorNear(image.At(figure.ToDevice(centre)), ToRgba(expected)))
          << "cell (" << iy << ", " << ix << ")";
    }
  }
}

TEST(Figure, HeatMapRowZeroIsAtTheBottom) {
  const TempDir dir;
  Figure figure(World(0, 0, 2, 2), Plain());
  Eigen::MatrixXd values(2, 1);
  values << 1.0,  // row 0: black in the occupancy map
      0.0;        // row 1: white
  figure.HeatMap(values, World(0, 0, 2, 2), Colormap::kOccupancy, 0.0, 1.0);
  figure.Save(dir / "rows.png");
  const PngImage image(dir / "rows.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.0, 0.5})), (Rgba{0, 0, 0, 255})));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.0, 1.5})), kWhite));
}

TEST(Figure, HeatMapCoversOnlyItsExtent) {
  const TempDir dir;
  Figure figure(World(0, 0, 4, 4), Plain());
  const Eigen::MatrixXd values = Eigen::MatrixXd::Ones(3, 3);
  figure.HeatMap(values, World(1, 1, 3, 3), Colormap::kOccupancy, 0.0, 1.0);
  figure.Save(dir / "extent.png");
  const PngImage image(dir / "extent.png");
  ASSERT_TRUE(image.ok());
  const Rgba black{0, 0, 0, 255};
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.1, 1.1})), black));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2.9, 2.9})), black));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.9, 2.0})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2.0, 3.1})), kWhite));
}

TEST(Figure, HeatMapNanCellsAreLeftWhite) {
  const TempDir dir;
  Figure figure(World(0, 0, 2, 2), Plain());
  Eigen::MatrixXd values(2, 2);
  values << kNaN, 1.0,  //
      0.5, kNaN;
  figure.HeatMap(values, World(0, 0, 2, 2), Colormap::kViridis, 0.0, 1.0);
  figure.Save(dir / "nan.png");
  const PngImage image(dir / "nan.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.5, 0.5})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.5, 1.5})), kWhite));
  EXPECT_TRUE(
      ColorNear(image.At(figure.ToDevice({1.5, 0.5})), ToRgba(MapColor(Colormap::kViridis, 1.0))));
  EXPECT_TRUE(
      ColorNear(image.At(figure.ToDevice({0.5, 1.5})), ToRgba(MapColor(Colormap::kViridis, 0.5))));
}

// Cairo makes no image over 32767 pixels on a side: a raster that wide is shrunk by blocks, each
// the mean of its cells.
TEST(Figure, HeatMapWiderThanCairosImagesIsDrawnFromBlockMeans) {
  const TempDir dir;
  Figure figure(World(0, 0, 40000, 20000), Plain());
  Eigen::MatrixXd values = Eigen::MatrixXd::Zero(2, 40000);
  values.rightCols(20000).setOnes();  // the east half black, the west half white
  figure.HeatMap(values, World(0, 0, 40000, 20000), Colormap::kOccupancy, 0.0, 1.0);
  figure.Save(dir / "wide.png");
  const PngImage image(dir / "wide.png");
  ASSERT_TRUE(image.ok());
  const Rgba black{0, 0, 0, 255};
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({10000, 5000})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({30000, 5000})), black));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({10000, 15000})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({30000, 15000})), black));
}

// A shrunk raster whose last block is partial: its cells must still fall where they are, not be
// stretched over the extent (which moved the east end by up to the factor's cells).
TEST(Figure, AShrunkHeatMapKeepsItsCellsInPlace) {
  const TempDir dir;
  Figure figure(World(0, 0, 8194, 100), Plain(8000));       // about one pixel a cell
  Eigen::MatrixXd values = Eigen::MatrixXd::Zero(2, 8194);  // shrunk by 3: 2732 pixels
  values.block(0, 8184, 2, 9).setOnes();  // three whole blocks of black, cells 8184 to 8192
  figure.HeatMap(values, World(0, 0, 8194, 100), Colormap::kOccupancy, 0.0, 1.0);
  figure.Save(dir / "shrunk.png");
  const PngImage image(dir / "shrunk.png");
  ASSERT_TRUE(image.ok());
  const Rgba black{0, 0, 0, 255};
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({8182.5, 50})), kWhite));  // stretched: black
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({8187.5, 50})), black));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({4000, 50})), kWhite));
}

// A heat map far larger than the world (1e12 times: device coordinates of 1e14 px) drew nothing:
// beyond Cairo's 24.8 fixed point, its image and clip were lost. Its visible part is drawn, with
// its cells where they are.
TEST(Figure, AHeatMapFarLargerThanTheWorldIsDrawnWhereItIsSeen) {
  const TempDir dir;
  Eigen::MatrixXd values(2, 2);
  values << 0.0, 1.0 / 3,  // row 0, at the bottom
      2.0 / 3, 1.0;
  // Not much beyond: at 1e17 px a double places the cells' boundary only to within 32 px.
  for (const double half : {2.0, 2e3, 2e6, 2e9, 2e12}) {
    Figure figure(World(0, 0, 4, 4), Plain());
    // The four cells meet at the world's centre.
    figure.HeatMap(values, World(2 - half, 2 - half, 2 + half, 2 + half), Colormap::kViridis, 0.0,
                   1.0);
    figure.Save(dir / "huge.png");
    const PngImage image(dir / "huge.png");
    ASSERT_TRUE(image.ok());
    for (int iy = 0; iy < 2; ++iy) {
      for (int ix = 0; ix < 2; ++ix) {
        const Rgba expected = ToRgba(MapColor(Colormap::kViridis, values(iy, ix)));
        for (const double inset : {0.05, 1.0, 1.95}) {
          const Vec2 p(ix == 0 ? 2.0 - inset : 2.0 + inset, iy == 0 ? 2.0 - inset : 2.0 + inset);
          EXPECT_TRUE(ColorNear(image.At(figure.ToDevice(p)), expected))
              << "half width " << half << ", cell (" << iy << ", " << ix << ") at " << p.x() << ", "
              << p.y();
        }
      }
    }
  }
}

// Cells thousands of pixels wide: Cairo's image sampling (16.16 fixed point) put the boundaries
// of a row of three cells 8000 px wide 12 px from where they are.
TEST(Figure, HeatMapCellsThousandsOfPixelsWideMeetWhereTheyShould) {
  const TempDir dir;
  Figure figure(World(0, 0, 3, 0.3), Plain(8000));
  Eigen::MatrixXd values(1, 3);
  values << 1.0, 0.0, 1.0;  // black, white, black
  figure.HeatMap(values, World(0, 0, 3, 0.3), Colormap::kOccupancy, 0.0, 1.0);
  figure.Save(dir / "wide_cells.png");
  const PngImage image(dir / "wide_cells.png");
  ASSERT_TRUE(image.ok());
  const Rgba black{0, 0, 0, 255};
  for (const double boundary : {1.0, 2.0}) {
    const Vec2 at = figure.ToDevice({boundary, 0.15});
    const Rgba left = boundary == 1.0 ? black : kWhite, right = boundary == 1.0 ? kWhite : black;
    EXPECT_TRUE(ColorNear(image.At(at - Vec2(2.0, 0.0)), left)) << "boundary " << boundary;
    EXPECT_TRUE(ColorNear(image.At(at + Vec2(2.0, 0.0)), right)) << "boundary " << boundary;
  }
}

// Seen only in part, reaching from the world's middle to far beyond it: drawn up to its edge.
TEST(Figure, AHeatMapReachingFarBeyondTheWorldEndsAtItsEdge) {
  const TempDir dir;
  const Eigen::MatrixXd values = Eigen::MatrixXd::Ones(3, 1000);
  for (const double far : {10.0, 1e7, 1e13, 1e300}) {
    Figure figure(World(0, 0, 4, 4), Plain());
    figure.HeatMap(values, World(2, 1, far, 3), Colormap::kOccupancy, 0.0, 1.0);
    figure.Save(dir / "far.png");
    const PngImage image(dir / "far.png");
    ASSERT_TRUE(image.ok());
    const Rgba black{0, 0, 0, 255};
    for (const double x : {2.05, 3.0, 3.95}) {
      EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({x, 2.0})), black)) << far << " at x " << x;
      EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({x, 3.05})), kWhite)) << far << " at x " << x;
      EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({x, 0.95})), kWhite)) << far << " at x " << x;
    }
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.95, 2.0})), kWhite)) << far;
  }
}

TEST(Figure, HeatMapPreconditions) {
  Figure figure(World(0, 0, 1, 1));
  EXPECT_THROW(figure.HeatMap(Eigen::MatrixXd(0, 0), World(0, 0, 1, 1), Colormap::kViridis, 0, 1),
               ContractError);
  EXPECT_THROW(
      figure.HeatMap(Eigen::MatrixXd::Zero(2, 2), World(0, 0, 1, 1), Colormap::kViridis, 1, 1),
      ContractError);
  // An infinite end maps every cell to NaN: a blank heat map, not a figure of the values.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(
      figure.HeatMap(Eigen::MatrixXd::Zero(2, 2), World(0, 0, 1, 1), Colormap::kViridis, -inf, 1),
      ContractError);
  EXPECT_THROW(
      figure.HeatMap(Eigen::MatrixXd::Zero(2, 2), World(0, 0, 1, 1), Colormap::kViridis, 0, inf),
      ContractError);
}

TEST(Figure, ColorbarIsDrawnRightOfThePlot) {
  const TempDir dir;
  FigureOptions options = Options(500);
  options.axes = false;
  options.colorbar = true;
  Figure figure(World(0, 0, 4, 4), options);
  const Eigen::MatrixXd values = Eigen::MatrixXd::Zero(1, 1);
  figure.HeatMap(values, World(0, 0, 4, 4), Colormap::kViridis, 0.0, 1.0, "value");
  figure.Save(dir / "colorbar.png");
  const PngImage image(dir / "colorbar.png");
  ASSERT_TRUE(image.ok());
  // The top of the bar is the colormap's high end, which appears nowhere in the heat map.
  const Rgba high = ToRgba(MapColor(Colormap::kViridis, 0.995));
  int right_of_plot = 0;
  const int plot_right = static_cast<int>(std::ceil(figure.ToDevice({4.0, 0.0}).x()));
  for (int y = 0; y < image.height(); ++y) {
    for (int x = plot_right + 1; x < image.width(); ++x)
      right_of_plot += Near(image.At(x, y), high, 3);
  }
  EXPECT_GT(right_of_plot, 0);
  // The bar runs along the plot's height from the low end at the bottom to the high end at the
  // top: right of the plot, the row at height fraction f shows the colour map at f (to within
  // the bar's steps), and not the colour of the mirrored height 1 - f.
  const double top = figure.ToDevice({0.0, 4.25}).y(), bottom = figure.ToDevice({0.0, -0.25}).y();
  for (const double f : {0.03, 0.25, 0.5, 0.75, 0.97}) {
    const int y = static_cast<int>(std::floor(bottom - f * (bottom - top)));
    // Whether the row shows the colour map at some t in [lo, hi].
    const auto shows = [&](double lo, double hi) {
      for (double t = std::max(lo, 0.0); t <= std::min(hi, 1.0); t += 0.001)
        for (int x = plot_right + 1; x < image.width(); ++x)
          if (Near(image.At(x, y), ToRgba(MapColor(Colormap::kViridis, t)), 2)) return true;
      return false;
    };
    EXPECT_TRUE(shows(f - 0.02, f + 0.02)) << "height fraction " << f;
    if (std::abs(f - 0.5) > 0.1) {
      EXPECT_FALSE(shows(0.97 - f, 1.03 - f)) << "height fraction " << f;
    }
  }
}

// Legend entries: a bar in each entry's colour, in entry order from the top, in the corner
// FigureOptions::legend names (or under the plot).
TEST(Figure, LegendSwatchesAreDrawnInTheirColoursWhereTheLegendGoes) {
  const TempDir dir;
  const Color crimson{0.8, 0.0, 0.2}, teal{0.0, 0.5, 0.5};
  struct Place {
    LegendPlace place;
    bool right, bottom, below;
  };
  for (const Place& place : {Place{LegendPlace::kTopRight, true, false, false},
                             Place{LegendPlace::kBottomLeft, false, true, false},
                             Place{LegendPlace::kTopLeft, false, false, false},
                             Place{LegendPlace::kBelow, false, false, true}}) {
    FigureOptions options = Plain();
    options.legend = place.place;
    Figure figure(World(0, 0, 4, 4), options);
    figure.AddLegend("first", crimson);
    figure.AddLegend("second", teal);
    figure.Save(dir / "legend.png");
    const PngImage image(dir / "legend.png");
    ASSERT_TRUE(image.ok());
    const Vec2 top_left = figure.ToDevice({0.0, 4.0}), bottom_right = figure.ToDevice({4.0, 0.0});
    const Vec2 middle = (top_left + bottom_right) / 2;
    double mean_row[2] = {0.0, 0.0};
    int index = 0;
    for (const Color& color : {crimson, teal}) {
      int n = 0;
      for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
          if (!Like(color)(image.At(x, y))) continue;
          ++n;
          mean_row[index] += y + 0.5;
          if (place.below) {
            EXPECT_GT(y, bottom_right.y()) << "entry " << index << " not under the plot";
            continue;
          }
          EXPECT_EQ(x + 0.5 > middle.x(), place.right) << "entry " << index << " at x " << x;
          EXPECT_EQ(y + 0.5 > middle.y(), place.bottom) << "entry " << index << " at y " << y;
        }
      }
      ASSERT_GE(n, 20) << "entry " << index << ": no swatch";  // a bar about 22 by 4 pixels
      mean_row[index] /= n;
      ++index;
    }
    if (!place.below) {
      EXPECT_LT(mean_row[0], mean_row[1]) << "the first entry is on top";
    }
  }
}

TEST(Figure, PointsAndLinesUseTheirColours) {
  const TempDir dir;
  Figure figure(World(0, 0, 4, 4), Plain());
  const Color green{0.0, 0.8, 0.0}, magenta{1.0, 0.0, 1.0};
  const std::vector<Vec2> points = {{1.0, 1.0}, {3.0, 3.0}};
  figure.Points(points, green, 4.0);
  figure.Line({0.0, 2.0}, {4.0, 2.0}, {magenta, 3.0, {}});
  figure.Save(dir / "points.png");
  const PngImage image(dir / "points.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.0, 1.0})), ToRgba(green)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({3.0, 3.0})), ToRgba(green)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2.0, 2.0}) + Vec2(0.5, 0.0)), ToRgba(magenta)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2.0, 3.0})), kWhite));
}

// Points scattered over the world as a log's are: on a few walls, with noise (deterministic).
std::vector<Vec2> WallPoints(std::size_t count, double size) {
  std::vector<Vec2> points;
  points.reserve(count);
  std::uint64_t state = 12345;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (std::size_t i = 0; i < count; ++i) {
    const double t = uniform() * size;
    const double wall = std::floor(uniform() * 4.0) / 4.0 * size + 0.1;
    const Vec2 p = i % 2 == 0 ? Vec2(t, wall) : Vec2(wall, t);
    points.push_back(p + 0.02 * Vec2(uniform() - 0.5, uniform() - 0.5));
  }
  return points;
}

// Above 20,000 points a Points call draws them as a raster layer; a PNG must not tell, at twice
// the figure's resolution (400 px) or less (3000 px: 9 MP, 1.33 times under the mask's cap).
class ManyPoints : public ::testing::TestWithParam<int> {};

TEST_P(ManyPoints, LookTheSameAsFewPointsInAPng) {
  const TempDir dir;
  const std::vector<Vec2> points = WallPoints(30000, 4.0);
  const Color blue{0.2, 0.4, 0.8};
  FigureOptions options = Plain(GetParam());
  options.max_height_px = GetParam();
  const double width_scale = GetParam() / 400.0;  // the points' discs are as large in the world
  Figure raster(World(0, 0, 4, 4), options);
  raster.Points(points, blue, 1.5 * width_scale);
  raster.Save(dir / "raster.png");
  Figure vector(World(0, 0, 4, 4), options);
  const std::span<const Vec2> all(points);
  for (std::size_t first = 0; first < all.size(); first += 10000)
    vector.Points(all.subspan(first, 10000), blue, 1.5 * width_scale);
  vector.Save(dir / "vector.png");

  const PngImage a(dir / "raster.png"), b(dir / "vector.png");
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  // The raster layer's antialiased edges differ by a shade; no pixel may be drawn in one and
  // blank in the other (white and the points' colour differ by 204 in red), and the ink agrees.
  double ink_raster = 0.0, ink_vector = 0.0;
  int worst = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      ink_raster += 255 - a.At(x, y).r;
      ink_vector += 255 - b.At(x, y).r;
      worst = std::max(worst, std::abs(a.At(x, y).r - b.At(x, y).r));
    }
  }
  ASSERT_GT(ink_vector, 5000 * 204.0 * width_scale * width_scale)
      << "the points cover part of the figure";
  EXPECT_NEAR(ink_raster / ink_vector, 1.0, 0.05);
  EXPECT_LT(worst, 96);
}

INSTANTIATE_TEST_SUITE_P(Figure, ManyPoints, ::testing::Values(400, 3000));

// A log's million points made a 50 MB SVG when each was an arc; as a raster layer its size
// follows the figure's, not the points'.
TEST(Figure, AnSvgOfAMillionPointsStaysSmall) {
  const TempDir dir;
  Figure figure(World(0, 0, 20, 20), Plain(800));
  figure.Points(WallPoints(1000000, 20.0), palette::kBlue, 1.5);
  figure.Save(dir / "points.svg");
  figure.Save(dir / "points.pdf");
  EXPECT_LT(fs::file_size(dir / "points.svg"), 2'000'000u);
  EXPECT_LT(fs::file_size(dir / "points.pdf"), 2'000'000u);
}

// A ray a million times longer than the figure keeps its direction (Cairo's fixed-point device
// coordinates would wrap its far end round).
TEST(Figure, AVeryLongLineKeepsItsDirection) {
  const TempDir dir;
  Figure figure(World(0, 0, 4, 4), Plain());
  const Color magenta{1.0, 0.0, 1.0};
  const Vec2 start(2.0, 1.0), direction(std::cos(0.3), std::sin(0.3));
  figure.Line(start, start + 1e7 * direction, {magenta, 3.0, {}});
  figure.Save(dir / "ray.png");
  const PngImage image(dir / "ray.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice(start + 1.5 * direction)), ToRgba(magenta)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({3.5, 0.5})), kWhite));
}

// Near the world's bound (and for UTM northings) the y tick labels are wider than the default
// margin: they must not run off the figure's left edge.
TEST(Figure, YTickLabelsOfLargeCoordinatesStayInsideTheFigure) {
  const TempDir dir;
  for (const double y0 : {1e9 - 10.0, -1e9, 5.4e6}) {
    Figure figure(World(0, y0, 10, y0 + 10), Options(600, 600));
    figure.Save(dir / "large.png");
    const PngImage image(dir / "large.png");
    ASSERT_TRUE(image.ok());
    for (int y = 0; y < image.height(); ++y) {
      for (int x = 0; x < 3; ++x) {
        ASSERT_TRUE(ColorNear(image.At(x, y), kWhite))
            << y0 << ": ink at (" << x << ", " << y << ")";
      }
    }
  }
}

// A requested size smaller than the margins (a colour bar's, a title's) must not leave a
// negative room for the plot, which flipped the world.
TEST(Figure, ASizeSmallerThanTheMarginsKeepsTheWorldTheRightWayRound) {
  FigureOptions narrow = Options(100, 800);
  narrow.colorbar = true;
  FigureOptions low = Options(800, 0);
  low.title = "low";
  for (const FigureOptions& options : {narrow, low}) {
    const Figure figure(World(0, 0, 1, 1), options);
    const Vec2 origin = figure.ToDevice({0, 0}), corner = figure.ToDevice({1, 1});
    EXPECT_LT(origin.x(), corner.x());
    EXPECT_GT(origin.y(), corner.y());
    EXPECT_GE(corner.x(), 0.0);
    EXPECT_LE(corner.x(), figure.width_px());
    EXPECT_GE(corner.y(), 0.0);
    EXPECT_LE(origin.y(), figure.height_px());
  }
}

// An arc of a thousand radians is one circle: Cairo would draw each of its 159 turns (of an arc of
// 1e300 radians, 65536 turns, for minutes).
TEST(Figure, AnArcOfManyTurnsIsDrawnAsOneCircle) {
  const TempDir dir;
  Figure circle(World(0, 0, 4, 4), Plain());
  circle.Arc({2, 2}, 1.0, 0.0, 2 * M_PI, {});
  circle.Save(dir / "circle.svg");
  Figure turns(World(0, 0, 4, 4), Plain());
  turns.Arc({2, 2}, 1.0, 0.0, 1000.0, {});
  turns.Save(dir / "turns.svg");
  EXPECT_LE(fs::file_size(dir / "turns.svg"), fs::file_size(dir / "circle.svg") + 200);
  // From 1e17 rad a turn is below the angle's resolution (1e17 + 2 pi == 1e17): still a circle,
  // as much ink as the one from 0.
  const auto ink = [&](double from, const char* name) {
    Figure figure(World(0, 0, 4, 4), Plain());
    figure.Arc({2, 2}, 1.0, from, from + 100.0, {});
    figure.Save(dir / name);
    return PngImage(dir / name).Count([](const testing::Rgba& p) { return p.r + p.g + p.b < 600; });
  };
  const int near = ink(0.0, "near.png");
  EXPECT_GT(near, 100);
  EXPECT_NEAR(ink(1e17, "far.png"), near, 0.05 * near);
}

// --- Tick labels -------------------------------------------------------------------------------

// The x labels are centred on their ticks: the last, at the plot's right end, reaches half its
// width beyond it, and "1000000" (48 px) was cut by the 16 px margin. The margin grows, as the
// left one does for wide y labels: the label is whole, centred on its tick.
TEST(Figure, TheLastXTickLabelIsWholeAndCentredOnItsTick) {
  const TempDir dir;
  for (const bool colorbar : {false, true}) {
    FigureOptions options = Options(800);
    options.padding_m = 0.0;
    options.colorbar = colorbar;
    const Figure figure(World(0, 0, 1e6, 5e5), options);
    figure.Save(dir / "labels.png");
    const PngImage image(dir / "labels.png");
    ASSERT_TRUE(image.ok());
    const Vec2 tick = figure.ToDevice({1e6, 0.0});
    // The labels' row: under the tick marks (5 px), above "x (m)".
    const int row = static_cast<int>(tick.y());
    const std::vector<std::pair<int, int>> labels = image.InkRuns(row + 6, row + 21, 5);
    ASSERT_GE(labels.size(), 3u);
    const auto [first, last] = labels.back();
    EXPECT_LT(last, image.width() - 2) << "the label runs to the figure's edge";
    EXPECT_NEAR((first + last + 1) / 2.0, tick.x(), 2.0) << "colour bar " << colorbar;
    EXPECT_GE(last + 1 - first, TextWidth("1000000", 11.0) - 3.0) << "colour bar " << colorbar;
  }
  // Labels that fit leave the layout as it was: the plot ends 16 px from the edge.
  const Figure small(World(0, 0, 10, 5), Options(800));
  EXPECT_NEAR(small.ToDevice({10.25, 0.0}).x(), 800 - 16, 1e-9);
}

// Colour-bar labels of values in the millions ("10000000") ran into the bar's label and off the
// figure: they are written in units of 10⁷, which the label names, and the label keeps clear.
TEST(Figure, WideColourBarLabelsAreWrittenInAPowerOfTen) {
  const TempDir dir;
  for (const double vmax : {1.0, 1e7, 2.5e-5}) {
    FigureOptions options = Options(500);
    options.colorbar = true;
    Figure figure(World(0, 0, 4, 4), options);
    Eigen::MatrixXd values(1, 2);
    values << 0.0, vmax;
    figure.HeatMap(values, World(0, 0, 4, 4), Colormap::kViridis, 0.0, vmax, "counts");
    figure.Save(dir / "colorbar.png");
    const PngImage image(dir / "colorbar.png");
    ASSERT_TRUE(image.ok());
    // Right of the bar and its tick marks (18 + 16 + 4 px right of the plot), the columns with
    // ink along the bar's height: the tick labels, a gap, the bar's label (rotated).
    const int from = static_cast<int>(std::ceil(figure.ToDevice({4.25, 0.0}).x())) + 39;
    const int top = static_cast<int>(figure.ToDevice({0.0, 4.25}).y()) - 6;
    const int bottom = static_cast<int>(figure.ToDevice({0.0, -0.25}).y()) + 6;
    std::vector<std::pair<int, int>> runs;  // split where 4 columns hold no ink
    int blank = 4;
    for (int x = from; x < image.width(); ++x) {
      bool ink = false;
      for (int y = top; y < bottom && !ink; ++y) {
        const Rgba p = image.At(x, y);
        ink = p.r < 160 && p.g < 160 && p.b < 160;
      }
      if (!ink) {
        ++blank;
        continue;
      }
      if (blank >= 4) {
        runs.emplace_back(x, x);
      } else {
        runs.back().second = x;
      }
      blank = 0;
    }
    ASSERT_EQ(runs.size(), 2u) << vmax << ": the tick labels run into the bar's label";
    EXPECT_LT(runs.back().second, image.width() - 2) << vmax;
    EXPECT_GE(runs.back().second - runs.back().first, 5) << vmax;  // text, rotated
  }
}

// --- TextWidth ---------------------------------------------------------------------------------

// The width the figures laid their labels out with before TextWidth kept one context a thread:
// a surface and a context made for each measurement. `text` is valid UTF-8.
double FreshContextWidth(const std::string& text, double size) {
  cairo_surface_t* surface = cairo_recording_surface_create(CAIRO_CONTENT_ALPHA, nullptr);
  cairo_t* cr = cairo_create(surface);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_destroy(cr);
  cairo_surface_destroy(surface);
  return extents.x_advance;
}

// Texts as measured, and as valid UTF-8 (bytes that are not become U+FFFD).
const std::vector<std::pair<std::string, std::string>> kTexts = {
    {"", ""},
    {"0", "0"},
    {"1000000", "1000000"},
    {"-2.5e+12", "-2.5e+12"},
    {"x (m)", "x (m)"},
    {"σ_ρ (m), ±3σ, θ error (deg)", "σ_ρ (m), ±3σ, θ error (deg)"},
    {"日本語の地図", "日本語の地図"},
    {"caf\xe9 \xff.json", "caf\xEF\xBF\xBD \xEF\xBF\xBD.json"}};

TEST(TextWidth, MeasuresWhatAContextOfItsOwnMeasures) {
  const double nan = kNaN;
  // Sizes in an order that changes at every call, and with the ones Cairo refuses (NaN puts a
  // context in error, after which it measures everything as 0) between the others.
  for (const double size : {11.0, 14.0, nan, 11.0, 0.5, 100.0, 0.0, 12.0, -5.0, 11.0, 1e-3}) {
    for (const auto& [text, valid] : kTexts) {
      const double expected = FreshContextWidth(valid, size);
      const double measured = TextWidth(text, size);
      EXPECT_EQ(measured, expected) << "'" << valid << "' at " << size;
    }
  }
  EXPECT_GT(TextWidth("1000000", 11.0), 40.0);
  EXPECT_EQ(TextWidth("1000000", 11.0), FreshContextWidth("1000000", 11.0));
}

// Each thread measures with its own context: the same widths, concurrently.
TEST(TextWidth, MeasuresTheSameOnSeveralThreads) {
  std::vector<double> expected;
  for (const auto& [text, valid] : kTexts) expected.push_back(FreshContextWidth(valid, 11.0));
  std::vector<std::vector<double>> measured(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < measured.size(); ++t) {
    threads.emplace_back([&, t] {
      for (int repeat = 0; repeat < 200; ++repeat)
        for (const auto& [text, valid] : kTexts)
          measured[t].push_back(TextWidth(text, repeat % 2 == 0 ? 11.0 : 17.0));
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (const std::vector<double>& widths : measured) {
    ASSERT_EQ(widths.size(), 200 * kTexts.size());
    for (std::size_t i = 0; i < kTexts.size(); ++i) EXPECT_EQ(widths[i], expected[i]) << i;
  }
}

// --- Non-finite and far input ------------------------------------------------------------------

// Cairo asserted on a NaN angle (an arc from -inf reduces to one), aborting the whole program.
TEST(Figure, AnArcWithANonFiniteAngleOrRadiusIsNotDrawn) {
  const TempDir dir;
  const double inf = std::numeric_limits<double>::infinity();
  const Color red{1.0, 0.0, 0.0};
  Figure figure(World(0, 0, 4, 4), Plain());
  figure.Arc({2, 2}, 1.0, 0.0, kNaN, {red, 3.0, {}});
  figure.Arc({2, 2}, 1.0, kNaN, 1.0, {red, 3.0, {}});
  figure.Arc({2, 2}, 1.0, -inf, 1.0, {red, 3.0, {}});
  figure.Arc({2, 2}, 1.0, 0.0, inf, {red, 3.0, {}});
  figure.Arc({2, 2}, kNaN, 0.0, 1.0, {red, 3.0, {}});
  figure.Arc({kNaN, 2}, 1.0, 0.0, 1.0, {red, 3.0, {}});
  figure.Arc({2, 2}, 1.0, 0.0, M_PI / 2, {palette::kBlue, 3.0, {}});  // still drawn after them
  figure.Save(dir / "arc.png");
  const PngImage image(dir / "arc.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image.Count(Like(red)), 0);
  EXPECT_GT(image.Count(Like(palette::kBlue)), 100);
}

// A polyline is broken at a non-finite point, as a line plot's is: Cairo drew a NaN as some
// point, with lines to it across the figure.
TEST(Figure, APolylineIsBrokenAtANonFinitePoint) {
  const TempDir dir;
  const Color red{1.0, 0.0, 0.0};
  for (const double bad : {kNaN, std::numeric_limits<double>::infinity()}) {
    Figure figure(World(0, 0, 4, 4), Plain());
    const std::vector<Vec2> points = {{1, 1}, {bad, 2}, {3, 3}, {3, 1}, {1, 1}, {1, bad}};
    figure.Polyline(points, false, {red, 3.0, {}});
    figure.Save(dir / "broken.png");
    const PngImage image(dir / "broken.png");
    ASSERT_TRUE(image.ok());
    // Only (3, 3) - (3, 1) - (1, 1) is drawn: every red pixel is near one of its two segments.
    const Vec2 corner = figure.ToDevice({3, 1});
    const Vec2 top = figure.ToDevice({3, 3}), left = figure.ToDevice({1, 1});
    int red_pixels = 0, astray = 0;
    for (int y = 0; y < image.height(); ++y) {
      for (int x = 0; x < image.width(); ++x) {
        if (!Like(red)(image.At(x, y))) continue;
        ++red_pixels;
        const Vec2 p(x + 0.5, y + 0.5);
        const bool on_vertical =
            std::abs(p.x() - corner.x()) < 3 && p.y() > top.y() - 3 && p.y() < corner.y() + 3;
        const bool on_horizontal =
            std::abs(p.y() - corner.y()) < 3 && p.x() > left.x() - 3 && p.x() < corner.x() + 3;
        astray += on_vertical || on_horizontal ? 0 : 1;
      }
    }
    EXPECT_GT(red_pixels, 800) << bad;
    EXPECT_EQ(astray, 0) << bad;
  }
}

// Cairo's fixed-point coordinates wrap beyond 8.4 million pixels: a line to a point 1e7 m away
// (1e9 px) stopped a metre from where it started, and a far polygon filled the wrong part.
TEST(Figure, ShapesReachingFarBeyondTheFigureAreClippedWhereTheyLeaveIt) {
  const TempDir dir;
  const Color red{1.0, 0.0, 0.0}, blue{0.0, 0.0, 1.0};
  for (const double far : {1e3, 1e5, 1e7, 1e9, 1e15}) {
    Figure figure(World(0, 0, 4, 4), Plain());
    const std::vector<Vec2> line = {{1, 1}, {far, 1}, {1, 1.5}};
    figure.Polyline(line, false, {red, 3.0, {}});
    // A band from x = 1 to far away, between y = 2.5 and 3.5.
    figure.FilledPolygon(Polygon{{{1, 2.5}, {far, 2.5}, {far, 3.5}, {1, 3.5}}}, blue);
    figure.Save(dir / "far.png");
    const PngImage image(dir / "far.png");
    ASSERT_TRUE(image.ok());
    for (const double x : {1.2, 2.0, 3.0, 3.9}) {
      EXPECT_TRUE(Like(red)(image.At(figure.ToDevice({x, 1.0})))) << far << " at x " << x;
      EXPECT_TRUE(Like(blue)(image.At(figure.ToDevice({x, 3.0})))) << far << " at x " << x;
      EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({x, 2.0})), kWhite)) << far << " at x " << x;
    }
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.5, 3.0})), kWhite)) << far;
  }
}

// A circle whose radius is a million pixels and more: Cairo filled the whole figure, or drew
// nothing. It is drawn from points along the part that can be seen.
TEST(Figure, CirclesFarLargerThanTheFigureAreDrawnWhereTheyPass) {
  const TempDir dir;
  const Color red{1.0, 0.0, 0.0}, blue{0.0, 0.0, 1.0};
  for (const double r : {10.0, 1e4, 1e6, 1e8, 1e12}) {
    Figure figure(World(0, 0, 4, 4), Plain());
    figure.FilledCircle(Circle{{2, 2.5 - r}, r}, red);               // the disc below y = 2.5
    figure.CircleOutline(Circle{{2, 3.5 + r}, r}, {blue, 3.0, {}});  // through (2, 3.5)
    figure.FilledCircle(Circle{{1e3 * r, 2}, r}, blue);              // far to the east
    figure.Save(dir / "circles.png");
    const PngImage image(dir / "circles.png");
    ASSERT_TRUE(image.ok());
    EXPECT_TRUE(Like(red)(image.At(figure.ToDevice({2, 2.3})))) << r;
    EXPECT_TRUE(Like(red)(image.At(figure.ToDevice({0.1, 0.1})))) << r;
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2, 2.7})), kWhite)) << r;
    EXPECT_TRUE(Like(blue)(image.At(figure.ToDevice({2, 3.5}) + Vec2(0.5, 0.0)))) << r;
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2, 3.8})), kWhite)) << r;
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2, 3.2})), kWhite)) << r;
  }
}

// A shape at a non-finite position is not drawn: Cairo drew it at some point.
TEST(Figure, ShapesAtNonFinitePositionsAreNotDrawn) {
  const TempDir dir;
  const Color red{1.0, 0.0, 0.0};
  Figure figure(World(0, 0, 4, 4), Plain());
  figure.FilledPolygon(Polygon{{{1, 1}, {3, 1}, {kNaN, 3}}}, red, {red, 2.0, {}});
  figure.Text({kNaN, 1.0}, "label", 30.0, red);
  figure.Text({1e12, 1.0}, "label", 30.0, red);
  figure.PoseMarker(Se2(kNaN, 1.0, 0.0), red, 20.0);
  figure.PoseMarker(Se2(2.0, 2.0, kNaN), red, 20.0);
  figure.FilledCircle(Circle{{kNaN, 2.0}, 1.0}, red);
  figure.FilledCircle(Circle{{2.0, 2.0}, kNaN}, red);
  figure.CircleOutline(Circle{{2.0, kNaN}, 1.0}, {red, 3.0, {}});
  const std::vector<Vec2> points = {{kNaN, 1.0}, {1e12, 1.0}};
  const std::vector<double> angles = {0.0, 0.0};
  figure.Ticks(points, angles, 40.0, {red, 3.0, {}});
  figure.CovarianceEllipse({kNaN, 1.0}, Mat2::Identity(), 1.0, {red, 3.0, {}});
  figure.Save(dir / "nowhere.png");
  const PngImage image(dir / "nowhere.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(Ink(image), 0);
}

// --- Contracts ---------------------------------------------------------------------------------

TEST(Figure, CovarianceEllipseWithANonPsdMatrixIsAContractError) {
  Figure figure(World(0, 0, 1, 1));
  Mat2 indefinite;
  indefinite << 1.0, 0.0, 0.0, -0.5;
  EXPECT_THROW(figure.CovarianceEllipse({0.5, 0.5}, indefinite, 2.0, {}), ContractError);
  Mat2 nan_matrix = Mat2::Constant(kNaN);
  EXPECT_THROW(figure.CovarianceEllipse({0.5, 0.5}, nan_matrix, 2.0, {}), ContractError);
  // Positive semi-definite (a degenerate ellipse) is accepted.
  Mat2 singular;
  singular << 0.04, 0.0, 0.0, 0.0;
  EXPECT_NO_THROW(figure.CovarianceEllipse({0.5, 0.5}, singular, 2.0, {}));
}

TEST(Figure, CovarianceEllipsePassesThroughTheNSigmaPoints) {
  const TempDir dir;
  Figure figure(World(-2, -2, 2, 2), Plain());
  Mat2 covariance;
  covariance << 0.25, 0.0, 0.0, 1.0;  // sigma_x = 0.5, sigma_y = 1
  const Color red{1.0, 0.0, 0.0};
  figure.CovarianceEllipse({0.0, 0.0}, covariance, 1.5, {red, 3.0, {}});
  figure.Save(dir / "ellipse.png");
  const PngImage image(dir / "ellipse.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.75, 0.0})), ToRgba(red)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.0, 1.5})), ToRgba(red)));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({0.0, 0.0})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.5, 0.0})), kWhite));
}

TEST(Figure, EmptyOrNonFiniteWorldIsAContractError) {
  EXPECT_THROW(Figure{Box2()}, ContractError);
  EXPECT_THROW(Figure{World(0, 0, kNaN, 1)}, ContractError);
  EXPECT_THROW(Figure{World(0, 0, std::numeric_limits<double>::infinity(), 1)}, ContractError);
}

// These made a figure that could not be saved ("invalid matrix", "invalid value"): refused when
// made, naming what is wrong.
TEST(Figure, ANonFinitePaddingOrAWorldWiderThanTheDoublesIsAContractError) {
  const double big = std::numeric_limits<double>::max();
  for (const double padding : {kNaN, std::numeric_limits<double>::infinity()}) {
    FigureOptions options;
    options.padding_m = padding;
    EXPECT_THROW(Figure(World(0, 0, 1, 1), options), ContractError) << padding;
  }
  EXPECT_THROW(Figure{World(-big, -big, big, big)}, ContractError);
  FigureOptions options;
  options.padding_m = 1e308;
  EXPECT_THROW(Figure(World(0, 0, 1, 1), options), ContractError);
}

TEST(Figure, TextOfANonFiniteOrNegativeSizeIsAContractError) {
  Figure figure(World(0, 0, 1, 1));
  EXPECT_THROW(figure.Text({0.5, 0.5}, "a", kNaN), ContractError);
  EXPECT_THROW(figure.Text({0.5, 0.5}, "a", std::numeric_limits<double>::infinity()),
               ContractError);
  EXPECT_THROW(figure.Text({0.5, 0.5}, "a", -12.0), ContractError);
  EXPECT_NO_THROW(figure.Text({0.5, 0.5}, "a", 0.0));
  const TempDir dir;
  EXPECT_NO_THROW(figure.Save(dir / "text.png"));  // the figure is still whole
}

// Cairo refuses a dash pattern with a negative length or none but zeros, and then draws nothing
// more: the figure failed only when saved ("invalid dash"), far from the style at fault. NaN and
// infinite lengths it takes, and draws as it may. Each is refused where the style is given,
// whether or not anything would be drawn.
TEST(Figure, ADashPatternCairoCannotDrawIsAContractErrorWhereTheStyleIsGiven) {
  const double inf = std::numeric_limits<double>::infinity();
  const Color red{1.0, 0.0, 0.0};
  const std::vector<Vec2> points = {{1, 1}, {3, 3}};
  const std::vector<double> angles = {0.0, 1.0};
  Figure figure(World(0, 0, 4, 4), Plain());
  for (const std::vector<double>& dashes : std::vector<std::vector<double>>{
           {-3.0}, {6.0, -1.0}, {kNaN, 4.0}, {6.0, inf}, {0.0}, {0.0, 0.0}}) {
    const LineStyle style{red, 2.0, dashes};
    const std::string pattern = ::testing::PrintToString(dashes);
    EXPECT_THROW(figure.Line({1, 1}, {3, 3}, style), ContractError) << pattern;
    EXPECT_THROW(figure.Line({1e3, 1e3}, {2e3, 1e3}, style), ContractError) << pattern;  // unseen
    EXPECT_THROW(figure.Polyline(points, false, style), ContractError) << pattern;
    EXPECT_THROW(figure.FilledPolygon(Polygon{{{1, 1}, {3, 1}, {2, 3}}}, red, style), ContractError)
        << pattern;
    EXPECT_THROW(figure.CircleOutline(Circle{{2, 2}, 1}, style), ContractError) << pattern;
    EXPECT_THROW(figure.Arc({2, 2}, 1.0, 0.0, 1.0, style), ContractError) << pattern;
    EXPECT_THROW(figure.CovarianceEllipse({2, 2}, Mat2::Identity(), 1.0, style), ContractError)
        << pattern;
    EXPECT_THROW(figure.Ticks(points, angles, 10.0, style), ContractError) << pattern;
  }
  try {
    figure.Line({1, 1}, {3, 3}, {red, 2.0, {6.0, -1.0}});
    ADD_FAILURE() << "no ContractError";
  } catch (const ContractError& e) {
    EXPECT_NE(std::string(e.what()).find("dash"), std::string::npos) << e.what();
  }
  // Dots (no length on) and plain dashes are drawn, and the figure is whole.
  figure.Line({1, 2}, {3, 2}, {red, 3.0, {0.0, 6.0}});
  figure.Line({1, 3}, {3, 3}, {red, 3.0, {6.0, 4.0}});
  const TempDir dir;
  ASSERT_NO_THROW(figure.Save(dir / "dashes.png"));
  const PngImage image(dir / "dashes.png");
  ASSERT_TRUE(image.ok());
  EXPECT_GT(image.Count(Like(red)), 100);
}

TEST(Figure, AHeatMapExtentNotFiniteOrOfNoAreaIsAContractError) {
  Figure figure(World(0, 0, 1, 1));
  const Eigen::MatrixXd values = Eigen::MatrixXd::Zero(2, 2);
  for (const Box2& extent :
       {World(kNaN, 0, 1, 1), World(0, 0, std::numeric_limits<double>::infinity(), 1), Box2(),
        World(0, 0, 0, 1), World(0, 0, 1, 0),
        // Finite, but not in pixels: nowhere to place it.
        World(-1e307, 0, 1e307, 1)}) {
    EXPECT_THROW(figure.HeatMap(values, extent, Colormap::kViridis, 0, 1), ContractError);
  }
  const TempDir dir;
  EXPECT_NO_THROW(figure.Save(dir / "heat.png"));
}

// Cairo stops drawing at a string that is not UTF-8; such bytes (a file name in the title) are
// shown as U+FFFD and the rest of the figure is drawn.
TEST(Figure, ATitleThatIsNotUtf8DoesNotBlankTheFigure) {
  const TempDir dir;
  FigureOptions options = Options(300, 300);
  options.title = "caf\xe9 \xff\xfe.json";
  Figure figure(World(0, 0, 4, 4), options);
  figure.FilledPolygon(Polygon{{{1.0, 1.0}, {3.0, 1.0}, {3.0, 3.0}, {1.0, 3.0}}}, palette::kBlack);
  figure.Save(dir / "title.png");
  const PngImage image(dir / "title.png");
  ASSERT_TRUE(image.ok());
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2, 2})), (Rgba{0, 0, 0, 255})));
}

// --- Scene drawing -----------------------------------------------------------------------------

Scan SimulatedScan(const Scene& scene, double outlier_probability = 0.0) {
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.outlier_probability = outlier_probability;
  Rng rng(7);
  return SimulateScan(SceneRayCaster(scene), sensor, *scene.default_pose, rng);
}

TEST(SceneDrawing, ScanFigureHasTheRequestedSizeAndShowsTheReadings) {
  const TempDir dir;
  const Scene scene = *BuiltinScene("l-room");
  const Scan scan = SimulatedScan(scene);
  Box2 bounds = scene.Bounds();
  bounds.extend(ScanBounds(scan));
  FigureOptions options = Options(640, 640);
  options.title = "l-room";
  Figure figure(bounds, options);
  DrawScene(figure, scene);
  DrawScan(figure, scan);
  EXPECT_EQ(figure.width_px(), 640);
  EXPECT_LE(figure.height_px(), 640);
  EXPECT_GE(figure.height_px(), 500);  // the l-room is square
  figure.Save(dir / "scan.png");
  const PngImage image(dir / "scan.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image.width(), 640);
  EXPECT_EQ(image.height(), figure.height_px());
  EXPECT_GT(image.Count(ToRgba(ScanStyle{}.valid)), 100);
  EXPECT_GT(image.Count(ToRgba(palette::kYellow)), 10);  // the pose marker

  // Every reading is a dot of the valid colour where it lies in the world.
  int readings = 0, misplaced = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    ++readings;
    const Vec2 d = figure.ToDevice(scan.PointInWorld(i));
    if (!InImage(image, d) || !Like(ScanStyle{}.valid)(image.At(d))) ++misplaced;
  }
  EXPECT_GT(readings, 900);
  EXPECT_EQ(misplaced, 0) << "of " << readings << " readings";

  // The scene: the wall (dark grey, 0.25) where the sensor's blind sector leaves it bare, the
  // clutter box and bin (orange at half alpha) at their centres.
  const Vec2 bare_wall(-3.0, -2.25);
  for (std::size_t i = 0; i < scan.size(); ++i)
    if (scan.IsValid(i)) {
      ASSERT_GT((scan.PointInWorld(i) - bare_wall).norm(), 0.3);
    }
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice(bare_wall)), (Rgba{64, 64, 64, 255}), 2));
  const Rgba clutter = OverWhite(palette::kOrange, 0.5);
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({-0.8, -2.3})), clutter, 2));  // the box
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({-2.3, -0.6})), clutter, 2));  // the bin

  // Empty space is background: inside the room and in the quadrant the L leaves out.
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({-1.5, 1.5})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.5, 1.5})), kWhite));
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({1.5, -1.5})), kWhite));

  // The pose marker points along the heading (45 degrees: up and to the right in the image).
  const Vec2 pose = figure.ToDevice(scan.pose.translation());
  const Vec2 heading(std::cos(scan.pose.theta()), -std::sin(scan.pose.theta()));  // y down
  EXPECT_TRUE(ColorNear(image.At(pose + 4.0 * heading), ToRgba(palette::kYellow), 2));
  EXPECT_TRUE(ColorNear(image.At(pose - 10.0 * heading), kWhite));

  // True normals: green ticks from each reading into the room. On the top wall (y = 3) they
  // point down in the image, and nothing is drawn beyond the wall.
  std::size_t top = scan.size();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i) &&
        (top == scan.size() || (scan.PointInWorld(i) - Vec2(-1.5, 3.0)).norm() <
                                   (scan.PointInWorld(top) - Vec2(-1.5, 3.0)).norm()))
      top = i;
  }
  ASSERT_LT((scan.PointInWorld(top) - Vec2(-1.5, 3.0)).norm(), 0.05);
  const Vec2 on_wall = figure.ToDevice(scan.PointInWorld(top));
  const auto green = [](const Rgba& p) { return p.g - p.r > 50 && p.g > p.b; };
  EXPECT_TRUE(green(image.At(on_wall + Vec2(0.0, 4.0))))
      << priormap::testing::Describe(image.At(on_wall + Vec2(0.0, 4.0)));
  EXPECT_TRUE(ColorNear(image.At(on_wall - Vec2(0.0, 4.0)), kWhite));
}

TEST(SceneDrawing, OutliersAreDrawnInTheOutlierColour) {
  const TempDir dir;
  const Scene scene = *BuiltinScene("square");
  const Scan clean = SimulatedScan(scene);
  const Scan noisy = SimulatedScan(scene, 0.3);
  for (const auto* scan : {&clean, &noisy}) {
    Figure figure(scene.Bounds(), Options(400, 400));
    DrawScan(figure, *scan);
    figure.Save(dir / "outliers.png");
    const PngImage image(dir / "outliers.png");
    ASSERT_TRUE(image.ok());
    const int outlier_pixels = image.Count(ToRgba(ScanStyle{}.outlier));
    if (scan == &clean) {
      EXPECT_EQ(outlier_pixels, 0);
    } else {
      EXPECT_GT(outlier_pixels, 50);
    }
    // Each reading is drawn where it lies: outliers (the simulator's truth) in the outlier
    // colour, the others in the valid colour. Readings under what is drawn later are left out:
    // the pose marker (12 pixels) over everything, an outlier's dot (radius 1.6 x 1.4) over the
    // valid readings within its reach.
    ASSERT_TRUE(scan->truth.has_value());
    std::vector<Vec2> outlier_points;
    for (std::size_t i = 0; i < scan->size(); ++i)
      if (scan->IsValid(i) && scan->truth->outlier[i] != 0)
        outlier_points.push_back(figure.ToDevice(scan->PointInWorld(i)));
    const Vec2 pose = figure.ToDevice(scan->pose.translation());
    int outliers = 0, valid = 0, wrong_outliers = 0, wrong_valid = 0;
    for (std::size_t i = 0; i < scan->size(); ++i) {
      if (!scan->IsValid(i)) continue;
      const Vec2 d = figure.ToDevice(scan->PointInWorld(i));
      ASSERT_TRUE(InImage(image, d)) << i;
      if ((d - pose).norm() < 14.0) continue;
      if (scan->truth->outlier[i] != 0) {
        ++outliers;
        wrong_outliers += Like(ScanStyle{}.outlier)(image.At(d)) ? 0 : 1;
        continue;
      }
      bool covered = false;
      for (const Vec2& o : outlier_points) covered = covered || (o - d).norm() < 1.6 * 1.4 + 1.5;
      if (covered) continue;
      ++valid;
      wrong_valid += Like(ScanStyle{}.valid)(image.At(d)) ? 0 : 1;
    }
    EXPECT_EQ(wrong_outliers, 0) << "of " << outliers;
    EXPECT_EQ(wrong_valid, 0) << "of " << valid;
    if (scan == &noisy) {
      EXPECT_GT(outliers, 100);
      EXPECT_GT(valid, 300);
    } else {
      EXPECT_EQ(outliers, 0);
      EXPECT_GT(valid, 900);
    }
  }
}

TEST(SceneDrawing, LogFigureHasTheRequestedSize) {
  const TempDir dir;
  const Scene scene = *BuiltinScene("corridor");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const Log log = SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 2.0, 2.0), 3);
  ASSERT_GT(log.scans.size(), 10u);
  const Box2 bounds = LogBounds(log);
  for (const Scan& scan : log.scans) EXPECT_TRUE(bounds.contains(scan.pose.translation()));
  Figure figure(bounds, Options(800, 800));
  DrawScene(figure, scene);
  DrawLog(figure, log, 2);
  EXPECT_EQ(figure.width_px(), 800);
  // The corridor is ten times longer than wide (plus padding): a short, wide figure.
  EXPECT_LT(figure.height_px(), 300);
  figure.Save(dir / "log.png");
  const PngImage image(dir / "log.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image.width(), figure.width_px());
  EXPECT_EQ(image.height(), figure.height_px());
  // The trajectory, a thin vermillion line (anti-aliased, so reddish rather than exact).
  const auto reddish = [](const Rgba& c) { return c.r - c.b > 100 && c.g < c.r; };
  EXPECT_GT(image.Count(reddish), 100);
  // ...through every scan's pose.
  int off_trajectory = 0;
  for (const Scan& scan : log.scans)
    off_trajectory += AnyNear(image, figure.ToDevice(scan.pose.translation()), 1, reddish) ? 0 : 1;
  EXPECT_EQ(off_trajectory, 0) << "of " << log.scans.size() << " poses";
  // The readings of the scans drawn (every other one) are bluish dots on the walls.
  const auto bluish = [](const Rgba& c) { return c.b - c.r > 30; };
  int missing = 0, drawn = 0;
  for (std::size_t k = 0; k < log.scans.size(); k += 2) {
    const Scan& scan = log.scans[k];
    for (std::size_t i = 0; i < scan.size(); i += 10) {
      if (!scan.IsValid(i)) continue;
      ++drawn;
      missing += bluish(image.At(figure.ToDevice(scan.PointInWorld(i)))) ? 0 : 1;
    }
  }
  EXPECT_GT(drawn, 100);
  EXPECT_EQ(missing, 0) << "of " << drawn << " readings";
  // The corridor between the trajectory's two legs (y = -0.3 and 0.3) is empty, and so is the
  // doorway in the upper wall (x in [1.5, 2.5]); the lower wall opposite it is drawn.
  for (const double x : {-6.0, -2.0, 0.0, 4.0, 7.0})
    EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({x, 0.0})), kWhite)) << "x = " << x;
  EXPECT_TRUE(ColorNear(image.At(figure.ToDevice({2.0, 1.0})), kWhite));
  EXPECT_LT(image.At(figure.ToDevice({2.0, -1.0})).r, 128);
}

TEST(SceneDrawing, ScanBoundsContainThePoseAndEveryValidReading) {
  const Scene scene = *BuiltinScene("l-room");
  const Scan scan = SimulatedScan(scene);
  const Box2 bounds = ScanBounds(scan);
  EXPECT_TRUE(bounds.contains(scan.pose.translation()));
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i)) {
      EXPECT_TRUE(bounds.contains(scan.PointInWorld(i))) << i;
    }
  }
  // ...and nothing much more: the l-room's walls span 6 m.
  EXPECT_LT(bounds.sizes().maxCoeff(), 6.1);
}

// --- Colours -----------------------------------------------------------------------------------

TEST(MapColor, ViridisEndpointsAreMatplotlibs) {
  const Color low = MapColor(Colormap::kViridis, 0.0);
  const Color high = MapColor(Colormap::kViridis, 1.0);
  EXPECT_NEAR(low.r, 0.267004, 1e-6);
  EXPECT_NEAR(low.g, 0.004874, 1e-6);
  EXPECT_NEAR(low.b, 0.329415, 1e-6);
  EXPECT_NEAR(high.r, 0.993248, 1e-6);
  EXPECT_NEAR(high.g, 0.906157, 1e-6);
  EXPECT_NEAR(high.b, 0.143936, 1e-6);
  EXPECT_EQ(low.a, 1.0);
  EXPECT_EQ(high.a, 1.0);
}

TEST(MapColor, OccupancyGoesFromWhiteToBlack) {
  const Color free = MapColor(Colormap::kOccupancy, 0.0);
  const Color occupied = MapColor(Colormap::kOccupancy, 1.0);
  const Color half = MapColor(Colormap::kOccupancy, 0.5);
  EXPECT_EQ(ToRgba(free).r + ToRgba(free).g + ToRgba(free).b, 3 * 255);
  EXPECT_EQ(ToRgba(occupied).r + ToRgba(occupied).g + ToRgba(occupied).b, 0);
  EXPECT_NEAR(half.r, 0.5, 1e-12);
  EXPECT_EQ(free.a, 1.0);
  EXPECT_EQ(occupied.a, 1.0);
}

TEST(MapColor, OutOfRangeValuesAreClampedAndNanIsTransparent) {
  for (Colormap map : {Colormap::kViridis, Colormap::kOccupancy}) {
    EXPECT_TRUE(ColorNear(ToRgba(MapColor(map, -3.0)), ToRgba(MapColor(map, 0.0))));
    EXPECT_TRUE(ColorNear(ToRgba(MapColor(map, 7.0)), ToRgba(MapColor(map, 1.0))));
    EXPECT_EQ(MapColor(map, kNaN).a, 0.0);
  }
}

TEST(MapColor, ViridisGetsBrighterAlongTheMap) {
  double previous = -1.0;
  for (int i = 0; i <= 20; ++i) {
    const Color c = MapColor(Colormap::kViridis, i / 20.0);
    const double luminance = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GT(luminance, previous) << i;
    previous = luminance;
  }
}

TEST(Color, FromHexReadsRgbAndRgba) {
  const Color orange = Color::FromHex("#ff8000");
  EXPECT_DOUBLE_EQ(orange.r, 1.0);
  EXPECT_DOUBLE_EQ(orange.g, 128.0 / 255.0);
  EXPECT_DOUBLE_EQ(orange.b, 0.0);
  EXPECT_DOUBLE_EQ(orange.a, 1.0);
  const Color translucent = Color::FromHex("#0A0b0C80");
  EXPECT_DOUBLE_EQ(translucent.r, 10.0 / 255.0);
  EXPECT_DOUBLE_EQ(translucent.g, 11.0 / 255.0);
  EXPECT_DOUBLE_EQ(translucent.b, 12.0 / 255.0);
  EXPECT_DOUBLE_EQ(translucent.a, 128.0 / 255.0);
}

TEST(Color, FromHexGivesBlackForAnythingElse) {
  for (const char* text : {"", "#", "ff8000", "#ff800", "#ff80000", "#ff8000801", "#ffgg00",
                           "#12345z", "#+f0000", "#-10000", " #ff8000", "#ff 000", "#0x1000"}) {
    const Color c = Color::FromHex(text);
    EXPECT_TRUE(c.r == 0.0 && c.g == 0.0 && c.b == 0.0 && c.a == 1.0) << "'" << text << "'";
  }
}

TEST(Color, WithAlphaKeepsTheColour) {
  const Color c = palette::kBlue.WithAlpha(0.25);
  EXPECT_EQ(c.r, palette::kBlue.r);
  EXPECT_EQ(c.g, palette::kBlue.g);
  EXPECT_EQ(c.b, palette::kBlue.b);
  EXPECT_EQ(c.a, 0.25);
}

TEST(Palette, CategoricalCyclesThroughDistinctColours) {
  for (int i = 0; i < 7; ++i) {
    for (int j = i + 1; j < 7; ++j) {
      EXPECT_FALSE(Near(ToRgba(palette::Categorical(i)), ToRgba(palette::Categorical(j)), 0))
          << i << " " << j;
    }
    EXPECT_TRUE(ColorNear(ToRgba(palette::Categorical(i + 7)), ToRgba(palette::Categorical(i))));
    EXPECT_TRUE(ColorNear(ToRgba(palette::Categorical(i - 7)), ToRgba(palette::Categorical(i))));
  }
}

}  // namespace
}  // namespace priormap::render
