#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/map_scan_figure.hpp>
#include <priormap/render/slam_figures.hpp>

#include "testing/png_image.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::render {
namespace {

using priorlets::Link;
using priormap::testing::HasTemporaryFile;
using priormap::testing::Like;
using priormap::testing::PixelPredicate;
using priormap::testing::PngImage;
using priormap::testing::ReadAll;
using priormap::testing::Rgba;
using priormap::testing::TempDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A corner seen from the origin: the wall x = 2 (beams below 30 deg), then the wall y = 1.15;
// beam 5 is an outlier, kept out of the model.
struct Synthetic {
  Scan scan;
  priorlets::MapScan map;
  priorlets::Posterior posterior;
};

Synthetic MakeSynthetic(std::size_t n = 41) {
  Synthetic s;
  Scan& scan = s.scan;
  scan.angles = EvenlySpacedAngles(n, DegToRad(-40), DegToRad(80));
  scan.sigma.assign(n, 0.01);
  scan.status.assign(n, BeamStatus::kValid);
  priorlets::MapScan& map = s.map;
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = scan.angles[i];
    const bool wall_x = phi < DegToRad(30);
    const double range = wall_x ? 2.0 / std::cos(phi) : 1.15 / std::sin(phi);
    const double normal = wall_x ? kPi : -kPi / 2;  // towards the sensor
    const double facing = phi + kPi;
    scan.ranges.push_back(range + 0.01 * std::sin(7.0 * static_cast<double>(i)));
    const bool inmodel = i != 5;
    map.rho.push_back(inmodel ? range : scan.ranges.back());
    map.alpha.push_back(inmodel ? facing + WrapAngle(normal - facing) : kNaN);
    map.initial_alpha.push_back(inmodel ? map.alpha.back() + 0.05 * std::cos(3.0 * phi) : kNaN);
    map.initial_alpha_sigma.push_back(inmodel ? 0.2 : kNaN);
    map.alpha_lower.push_back(inmodel ? facing - DegToRad(89) : kNaN);
    map.alpha_upper.push_back(inmodel ? facing + DegToRad(89) : kNaN);
    map.inmodel.push_back(inmodel ? 1 : 0);
    if (inmodel) map.inmodel_beams.push_back(i);
  }
  scan.ranges[5] = 0.8;
  for (std::size_t j = 0; j + 1 < map.inmodel_beams.size(); ++j) {
    const bool corner = scan.angles[map.inmodel_beams[j]] < DegToRad(30) &&
                        scan.angles[map.inmodel_beams[j + 1]] >= DegToRad(30);
    map.links.push_back(corner ? Link::kDifferentRegion : Link::kSameRegion);
  }
  map.feasible = true;

  priorlets::Posterior& post = s.posterior;
  const std::size_t m = map.inmodel_beams.size();
  post.computed = true;
  post.dof.free = 3;
  post.dof.extrinsic = 3;
  post.dof.intrinsic = 2;
  post.prior_std_rho.assign(n, kNaN);
  post.posterior_std_rho.assign(n, kNaN);
  priorlets::Eigenvariation v;
  v.sigma = 0.01;
  v.rho.assign(n, kNaN);
  v.alpha = v.rho;
  v.intrinsic_fraction = 1.0;
  for (std::size_t b : map.inmodel_beams) {
    post.prior_std_rho[b] = 0.01;
    post.posterior_std_rho[b] = 0.002 + 0.001 * std::cos(scan.angles[b]);
    v.rho[b] = 1.0 / std::sqrt(static_cast<double>(m));
  }
  post.intrinsic_eigenvariations = {v, v};
  post.range_covariance =
      Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m), 2e-6);
  post.range_covariance.diagonal().array() += 4e-6;
  return s;
}

// Pixels of the heat map's top colour: only panel (e) and its colour bar use the colour map.
int HeatMapPixels(const PngImage& image) {
  return image.Count(Like(MapColor(Colormap::kViridis, 1.0)));
}

TEST(MapScanFigure, SavesPngSvgAndPdfOfItsSize) {
  const TempDir dir;
  const Synthetic s = MakeSynthetic();
  const MapScanFigure figure(s.scan, s.map, s.posterior, {.width_px = 1000, .title = "test"});
  figure.Save(dir / "f.png");
  figure.Save(dir / "f.svg");
  figure.Save(dir / "f.pdf");
  const PngImage png(dir / "f.png");
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png.width(), 1000);
  EXPECT_EQ(png.height(), figure.height_px());
  EXPECT_GT(figure.height_px(), figure.width_px());  // three rows of two panels
  EXPECT_TRUE(ReadAll(dir / "f.svg").starts_with("<?xml"));
  EXPECT_NE(ReadAll(dir / "f.svg").find("<svg"), std::string::npos);
  EXPECT_TRUE(ReadAll(dir / "f.pdf").starts_with("%PDF"));
  EXPECT_FALSE(HasTemporaryFile(dir.path()));
}

TEST(MapScanFigure, DrawsTheCovarianceOnlyWhenThePosteriorWasComputed) {
  const TempDir dir;
  Synthetic s = MakeSynthetic();
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "with.png");
  s.posterior = priorlets::Posterior{};
  s.posterior.note = "dim Free 5000 > max_free_dimension";
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "without.png");
  EXPECT_GT(HeatMapPixels(PngImage(dir / "with.png")), 500);
  EXPECT_EQ(HeatMapPixels(PngImage(dir / "without.png")), 0);
}

TEST(MapScanFigure, DownsamplesALargeCovariance) {
  const TempDir dir;
  const Synthetic s = MakeSynthetic(701);
  ASSERT_EQ(s.posterior.range_covariance.rows(), 700);
  const MapScanFigure figure(s.scan, s.map, s.posterior, {.max_heat_map_cells = 100});
  figure.Save(dir / "large.png");
  EXPECT_GT(HeatMapPixels(PngImage(dir / "large.png")), 500);
}

// The mean position (pixel centres) of the pixels satisfying `predicate`, and their number.
std::pair<Vec2, int> Centroid(const PngImage& image, const PixelPredicate& predicate) {
  Vec2 sum = Vec2::Zero();
  int n = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      if (!predicate(image.At(x, y))) continue;
      sum += Vec2(x + 0.5, y + 0.5);
      ++n;
    }
  }
  return {n > 0 ? Vec2(sum / n) : sum, n};
}

// Whether a pixel within one pixel (per axis) of the device point satisfies `predicate`.
bool NearPixel(const PngImage& image, const Vec2& device, const PixelPredicate& predicate) {
  const int cx = static_cast<int>(std::floor(device.x()));
  const int cy = static_cast<int>(std::floor(device.y()));
  for (int y = cy - 1; y <= cy + 1; ++y)
    for (int x = cx - 1; x <= cx + 1; ++x)
      if (x >= 0 && y >= 0 && x < image.width() && y < image.height() && predicate(image.At(x, y)))
        return true;
  return false;
}

// With no reading in the model, panel (a) shows every reading as an outlier: a cross where the
// reading lies in the sensor frame (x to the right, y up), around the sensor's marker at the
// origin; and with no posterior, no heat map. The panel's scale is not known to the test: it is
// the one of pixels per metre, found by search, that puts a cross under every reading (the
// sensor's yellow marker, drawn nowhere else, is the origin).
TEST(MapScanFigure, DrawsWithoutInModelPointsOrGroundTruth) {
  const TempDir dir;
  Synthetic s = MakeSynthetic();
  s.map.inmodel.assign(s.scan.size(), 0);
  s.map.inmodel_beams.clear();
  s.map.links.clear();
  s.posterior = priorlets::Posterior{};
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "empty.png");
  const PngImage image(dir / "empty.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(HeatMapPixels(image), 0);

  const auto [origin, marker_pixels] = Centroid(image, Like(palette::kYellow));
  ASSERT_GT(marker_pixels, 20);
  // In the top-left panel.
  EXPECT_LT(origin.x(), image.width() / 2.0);
  EXPECT_LT(origin.y(), image.height() / 2.0);

  const PixelPredicate cross = Like(palette::kVermillion);
  std::vector<Vec2> readings;
  for (std::size_t i = 0; i < s.scan.size(); ++i)
    if (s.scan.IsValid(i)) readings.push_back(s.scan.PointInSensorFrame(i));
  ASSERT_EQ(readings.size(), s.scan.size());
  std::size_t best = 0;
  double best_scale = 0.0;
  for (double scale = 20.0; scale <= 400.0; scale += 0.1) {
    std::size_t found = 0;
    for (const Vec2& p : readings)
      found += NearPixel(image, origin + scale * Vec2(p.x(), -p.y()), cross) ? 1 : 0;
    if (found > best) {
      best = found;
      best_scale = scale;
    }
  }
  EXPECT_EQ(best, readings.size()) << "at " << best_scale << " pixels per metre";
  // The readings span most of the panel: a scale of about 600 / 3.6 m.
  EXPECT_GT(best_scale, 100.0);
  // Under the sensor (beams at negative angles, y < 0) there are crosses: the panel's y is up.
  const Vec2 below = origin + best_scale * Vec2(readings.front().x(), -readings.front().y());
  EXPECT_GT(below.y(), origin.y() + 50.0);
  EXPECT_TRUE(NearPixel(image, below, cross));
}

TEST(MapScanFigure, RejectsAMapScanOfAnotherScan) {
  Synthetic s = MakeSynthetic();
  s.map.rho.pop_back();
  EXPECT_THROW(MapScanFigure(s.scan, s.map, s.posterior), ContractError);
  s = MakeSynthetic();
  s.posterior.posterior_std_rho.pop_back();
  EXPECT_THROW(MapScanFigure(s.scan, s.map, s.posterior), ContractError);
}

// The figure's height follows its width (1.2 times): a width that fits Cairo's images gives a
// height that does not. Refused when made, before any panel is drawn.
TEST(MapScanFigure, ASizeBeyondTheLimitsIsRefusedWhenMade) {
  const Synthetic s = MakeSynthetic();
  try {
    const MapScanFigure figure(s.scan, s.map, s.posterior, {.width_px = 28000});
    ADD_FAILURE() << "made a figure of " << figure.width_px() << " x " << figure.height_px();
  } catch (const ContractError& e) {
    EXPECT_NE(std::string(e.what()).find("28000 x 33600 px"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MapScanFigure(s.scan, s.map, s.posterior, {.width_px = 8000}), ContractError);
  const MapScanFigure largest(s.scan, s.map, s.posterior, {.width_px = 7400});
  EXPECT_TRUE(FigureSizeFits(largest.width_px(), largest.height_px()));
}

// A study of 12 days: the time axis ends on "1000000" (48 px) at the figure's right edge, which
// cut it (20 px margin). The panel's margin grows: the label is whole, centred on its tick.
TEST(StudyPlot, TheLastTimeLabelIsWholeAtTheFiguresEdge) {
  const TempDir dir;
  slam::StudyResult study;
  study.times = {0.0, 5e5, 1e6};
  slam::RunTrace run;
  run.error.assign(3, Vec3(0.1, 0.2, 0.01));
  run.sigma.assign(3, Vec3(0.2, 0.2, 0.02));
  run.nees = {2.0, 3.0, 4.0};
  study.with_prior = {run};
  study.without_prior = {run};
  study.nees_band_low = 1.5;
  study.nees_band_high = 4.5;
  const StudyPlot plot(study, StudyPlotKind::kNees, {.width_px = 800});
  plot.Save(dir / "nees.png");
  const PngImage image(dir / "nees.png");
  ASSERT_TRUE(image.ok());
  // The x labels' row: right under the frame, whose bottom edge is the lowest row darker than
  // the grid (anti-aliased, it may be grey) along most of the plot's width.
  const auto frame = [](const Rgba& p) { return p.r < 200; };
  int bottom = -1;
  for (int y = 0; y < image.height(); ++y) {
    int dark = 0;
    for (int x = 0; x < image.width(); ++x) dark += frame(image.At(x, y)) ? 1 : 0;
    if (dark > image.width() / 2) bottom = y;
  }
  ASSERT_GT(bottom, 0);
  std::vector<std::pair<int, int>> labels;  // runs of columns with ink, 5 blank ones apart
  int blank = 5;
  for (int x = 0; x < image.width(); ++x) {
    bool ink = false;
    for (int y = bottom + 5; y < bottom + 18; ++y) ink = ink || image.At(x, y).r < 128;
    if (!ink) {
      ++blank;
      continue;
    }
    if (blank >= 5) {
      labels.emplace_back(x, x);
    } else {
      labels.back().second = x;
    }
    blank = 0;
  }
  ASSERT_GE(labels.size(), 2u);
  const auto [first, last] = labels.back();
  EXPECT_LT(last, image.width() - 2) << "the label runs to the figure's edge";
  EXPECT_GE(last + 1 - first, TextWidth("1000000", 11.0) - 3.0);
  // Centred on the frame's right edge: the rightmost column dark down most of the plot.
  int right = -1;
  for (int x = 0; x < image.width(); ++x) {
    int dark = 0;
    for (int y = 0; y < bottom; ++y) dark += frame(image.At(x, y)) ? 1 : 0;
    if (dark > bottom / 2) right = x;
  }
  ASSERT_GT(right, 0);
  EXPECT_NEAR((first + last + 1) / 2.0, right, 2.0);
}

// A closed map (a full-turn scan) has one more link, from its last point round to its first:
// its border is marked in panel (a) as any other, and the MAP polyline of panel (c) goes round.
TEST(MapScanFigure, DrawsTheClosingLinkOfAFullTurn) {
  const TempDir dir;
  Synthetic s = MakeSynthetic();
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "open.png");
  s.map.closed = true;
  s.map.closing_link = Link::kDifferentRegion;
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "border.png");
  s.map.closing_link = Link::kSameRegion;
  MapScanFigure(s.scan, s.map, s.posterior).Save(dir / "round.png");
  const PngImage open(dir / "open.png"), border(dir / "border.png"), round(dir / "round.png");
  const auto orange = [](const PngImage& image) { return image.Count(Like(palette::kOrange)); };
  // A border marker is 2 px wide and about 7 % of the panel long: well over 20 pixels.
  EXPECT_GT(orange(border), orange(open) + 20);
  EXPECT_EQ(orange(round), orange(open));
  // The chord from the last point to the first, about a panel wide, in the MAP's grey.
  const auto gray = [](const PngImage& image) { return image.Count(Like(palette::kGray)); };
  EXPECT_GT(gray(round), gray(open) + 50);
}

}  // namespace
}  // namespace priormap::render
