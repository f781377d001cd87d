// The figure of a MAP scan and its posterior (de la Puente & Censi, Figs. 3-6), drawn as panels
// of one canvas.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/render/map_scan_figure.hpp>
#include <priormap/render/ticks.hpp>

#include "canvas.hpp"
#include "plot_panel.hpp"

namespace priormap::render {
namespace {

using detail::LegendEntry;
using detail::Marker;
using detail::Panel;
using detail::PanelOptions;
using detail::Rect;
using priorlets::Link;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const Color kMeasured = palette::kGray;
const Color kCorrected = palette::kBlue;
const Color kRegionBorder = palette::kOrange;
const Color kSurfaceBorder = palette::kBlack;
const Color kOutlier = palette::kVermillion;
const Color kTruth = palette::kGreen.WithAlpha(0.55);
const std::vector<double> kDashed{5.0, 3.0};

struct Inputs {
  const Scan& scan;
  const priorlets::MapScan& map;
  const priorlets::Posterior& posterior;
  const MapScanFigureOptions& options;
  Box2 world;  // sensor frame, padded
};

bool InModel(const priorlets::MapScan& map, std::size_t beam) {
  return map.inmodel[beam] != 0;
}

Vec2 Corrected(const Inputs& in, std::size_t beam, double delta_rho = 0.0) {
  return (in.map.rho[beam] + delta_rho) * UnitVector(in.scan.angles[beam]);
}

// A length with a unit that suits it: "8.2 µm", "0.31 mm", "1.2 cm", "0.41 m".
std::string Length(double metres) {
  const double a = std::abs(metres);
  if (a < 1e-4) return fmt::format("{:.2g} µm", metres * 1e6);
  if (a < 0.01) return fmt::format("{:.2g} mm", metres * 1e3);
  if (a < 1.0) return fmt::format("{:.2g} cm", metres * 1e2);
  return fmt::format("{:.3g} m", metres);
}

// The 1, 2 or 5 times a power of ten nearest to x on a log scale (1 for x <= 1).
double NiceFactor(double x) {
  if (!(x > 1.0) || !std::isfinite(x)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(x)));
  double best = magnitude;
  for (double factor : {2.0, 5.0, 10.0}) {
    if (std::abs(std::log(factor * magnitude / x)) < std::abs(std::log(best / x)))
      best = factor * magnitude;
  }
  return best;
}

std::string Plural(std::size_t n, const char* word) {
  return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s");
}

Box2 SensorFrameBounds(const Scan& scan, const priorlets::MapScan& map) {
  Box2 box(Vec2::Zero(), Vec2::Zero());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    box.extend(scan.PointInSensorFrame(i));
    if (InModel(map, i)) box.extend(map.rho[i] * UnitVector(scan.angles[i]));
  }
  const double pad = 0.06 * std::max(box.sizes().maxCoeff(), 0.5);
  return {box.min() - Vec2::Constant(pad), box.max() + Vec2::Constant(pad)};
}

// Link l of the in-model points, between points l and l + 1; in a closed map (a full turn) the
// last one, l = links.size(), is the closing link from the last point round to the first.
Link LinkAt(const priorlets::MapScan& map, std::size_t l) {
  return l < map.links.size() ? map.links[l] : map.closing_link;
}
std::size_t DrawnLinks(const priorlets::MapScan& map) {
  return map.links.size() + (map.closed ? 1 : 0);
}

// The in-model points as a polyline, broken where the surface changes (different_surface);
// round to the first point again when the map is closed.
std::vector<Vec2> SurfacePolyline(const Inputs& in, const std::vector<double>& delta_rho) {
  std::vector<Vec2> points;
  const std::vector<std::size_t>& beams = in.map.inmodel_beams;
  const auto point = [&](std::size_t beam) {
    return Corrected(in, beam, delta_rho.empty() ? 0.0 : delta_rho[beam]);
  };
  for (std::size_t j = 0; j < beams.size(); ++j) {
    if (j > 0 && in.map.links[j - 1] == Link::kDifferentSurface) points.emplace_back(kNaN, kNaN);
    points.push_back(point(beams[j]));
  }
  if (in.map.closed && !beams.empty() && in.map.closing_link != Link::kDifferentSurface)
    points.push_back(point(beams.front()));
  return points;
}

// --- (a) the scan, the corrected points and the topology (Figs. 3 and 5) ----------------------

void DrawScanPanel(cairo_t* cr, const Rect& cell, const Inputs& in) {
  const Panel panel(cr, cell, in.world.min().x(), in.world.max().x(), in.world.min().y(),
                    in.world.max().y(),
                    {.title = "(a) Measured and corrected scan, topology (sensor frame)",
                     .x_label = "x (m)",
                     .y_label = "y (m)",
                     .equal_aspect = true,
                     .legend_row = true});
  panel.DrawFrame();
  std::vector<Vec2> measured, corrected, outliers;
  for (std::size_t i = 0; i < in.scan.size(); ++i) {
    if (!in.scan.IsValid(i)) continue;
    measured.push_back(in.scan.PointInSensorFrame(i));
    if (InModel(in.map, i)) {
      corrected.push_back(Corrected(in, i));
    } else {
      outliers.push_back(measured.back());
    }
  }
  panel.Dots(measured, kMeasured, 1.7);
  // A short radial line across each border, between the two corrected points it separates.
  const double half_length = 0.035 * in.world.sizes().maxCoeff();
  const std::vector<std::size_t>& beams = in.map.inmodel_beams;
  for (std::size_t j = 0; j < DrawnLinks(in.map); ++j) {
    const Link link = LinkAt(in.map, j);
    if (link == Link::kSameRegion) continue;
    const std::size_t next = j + 1 < beams.size() ? j + 1 : 0;
    const Vec2 mid = 0.5 * (Corrected(in, beams[j]) + Corrected(in, beams[next]));
    const Vec2 u = mid.norm() > 0.0 ? Vec2(mid.normalized()) : Vec2::UnitX();
    const bool surface = link == Link::kDifferentSurface;
    panel.Segment(mid - half_length * u, mid + half_length * u,
                  surface ? kSurfaceBorder : kRegionBorder, 2.0,
                  surface ? std::span<const double>() : kDashed);
  }
  panel.Dots(corrected, kCorrected, 1.1);
  panel.Crosses(outliers, kOutlier, 3.5);
  panel.PoseMarker(Vec2::Zero(), 0.0, palette::kYellow, 12.0);
  panel.LegendRow({{"measured", kMeasured, Marker::kDot},
                   {"corrected", kCorrected, Marker::kDot},
                   {"region border", kRegionBorder, Marker::kLine, kDashed},
                   {"surface border", kSurfaceBorder, Marker::kLine},
                   {"outlier (not in model)", kOutlier, Marker::kCross}});
}

// --- (b) normal angles per beam (Fig. 4) ----------------------------------------------------

void DrawNormalPanel(cairo_t* cr, const Rect& cell, const Inputs& in) {
  const Scan& scan = in.scan;
  // Every angle as phi + 180 deg + its incidence, the engine's own unwrapping: continuous along
  // the scan, and a polygon's walls are steps.
  const auto unwrapped = [&](std::size_t i, double alpha) {
    const double facing = scan.angles[i] + kPi;
    return std::isfinite(alpha) ? RadToDeg(facing + WrapAngle(alpha - facing)) : kNaN;
  };
  std::vector<Vec2> lower, upper, initial, corrected, truth;
  double y_lo = std::numeric_limits<double>::infinity(), y_hi = -y_lo;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double x = RadToDeg(scan.angles[i]);
    const bool in_model = InModel(in.map, i);
    const auto add = [&](std::vector<Vec2>& series, double alpha) {
      const double y = unwrapped(i, alpha);
      series.emplace_back(x, y);
      if (std::isfinite(y)) {
        y_lo = std::min(y_lo, y);
        y_hi = std::max(y_hi, y);
      }
    };
    add(lower, in_model ? in.map.alpha_lower[i] : kNaN);
    add(upper, in_model ? in.map.alpha_upper[i] : kNaN);
    add(initial, in_model ? in.map.initial_alpha[i] : kNaN);
    add(corrected, in_model ? in.map.alpha[i] : kNaN);
    if (scan.truth) add(truth, scan.IsValid(i) ? scan.truth->alpha[i] : kNaN);
  }
  if (!(y_lo < y_hi)) {
    y_lo = 0.0;
    y_hi = 360.0;
  }
  const double pad = 0.04 * (y_hi - y_lo);
  const double x_lo = RadToDeg(scan.angles.front()), x_hi = RadToDeg(scan.angles.back());
  const Panel panel(cr, cell, x_lo, std::max(x_hi, x_lo + 1e-6), y_lo - pad, y_hi + pad,
                    {.title = "(b) Normal angles (α = φ + 180° + incidence)",
                     .x_label = "beam angle φ (deg)",
                     .y_label = "normal angle α (deg)",
                     .legend_row = true});
  panel.DrawFrame();
  panel.Polyline(lower, palette::kGray, 0.8);
  panel.Polyline(upper, palette::kGray, 0.8);
  if (scan.truth) panel.Polyline(truth, kTruth, 4.0);
  panel.Polyline(initial, palette::kSkyBlue, 1.2);
  panel.Polyline(corrected, palette::kVermillion, 1.5);
  std::vector<LegendEntry> legend{{"initial", palette::kSkyBlue, Marker::kLine},
                                  {"corrected", palette::kVermillion, Marker::kLine}};
  if (scan.truth) legend.push_back({"ground truth", kTruth, Marker::kLine, {}, 4.0});
  legend.push_back({"bounds", palette::kGray, Marker::kLine, {}, 1.0});
  panel.LegendRow(legend);
}

// --- (c) intrinsic scan eigenvariations (Fig. 6a-b) ------------------------------------------

void DrawEigenvariationPanel(cairo_t* cr, const Rect& cell, const Inputs& in) {
  const std::vector<priorlets::Eigenvariation>& all = in.posterior.intrinsic_eigenvariations;
  const std::size_t count =
      in.posterior.computed
          ? std::min(all.size(), static_cast<std::size_t>(std::max(in.options.eigenvariations, 0)))
          : 0;
  // Each variation, exaggerated by k, as the varied scans rho + k sigma v and rho - k sigma v.
  std::vector<double> k(count), largest(count);
  std::vector<std::vector<Vec2>> varied;
  Box2 world = in.world;
  for (std::size_t e = 0; e < count; ++e) {
    double max_v = 0.0;
    for (double v : all[e].rho) {
      if (std::isfinite(v)) max_v = std::max(max_v, std::abs(v));
    }
    largest[e] = all[e].sigma * max_v;
    k[e] = NiceFactor(in.options.eigenvariation_extent_fraction * in.world.sizes().maxCoeff() /
                      largest[e]);
    for (const double sign : {1.0, -1.0}) {
      std::vector<double> delta(all[e].rho.size());
      for (std::size_t i = 0; i < delta.size(); ++i)
        delta[i] = sign * k[e] * all[e].sigma * all[e].rho[i];
      varied.push_back(SurfacePolyline(in, delta));
      for (const Vec2& p : varied.back()) {
        if (p.allFinite()) world.extend(p);
      }
    }
  }
  std::string factors;
  for (double f : k) factors += fmt::format("{}{:g}", factors.empty() ? "" : ", ", f);
  const Panel panel(
      cr, cell, world.min().x(), world.max().x(), world.min().y(), world.max().y(),
      {.title = count == 0
                    ? std::string("(c) Intrinsic eigenvariations")
                    : fmt::format("(c) Intrinsic eigenvariations ρ ± k·σ·v, k = {}", factors),
       .x_label = "x (m)",
       .y_label = "y (m)",
       .equal_aspect = true,
       .legend_row = true});
  if (count == 0) {
    panel.DrawNote(!in.posterior.computed
                       ? "Posterior not computed: " + in.posterior.note
                       : fmt::format("No intrinsic eigenvariation (dim Intr = {}).",
                                     in.posterior.dof.intrinsic));
    return;
  }
  panel.DrawFrame();
  panel.Polyline(SurfacePolyline(in, {}), palette::kGray, 1.0);
  std::vector<LegendEntry> legend;
  const Color colors[] = {palette::kBlue, palette::kVermillion, palette::kGreen, palette::kPurple,
                          palette::kOrange};
  for (std::size_t e = 0; e < count; ++e) {
    const Color color = colors[e % std::size(colors)];
    panel.Polyline(varied[2 * e], color, 1.5);
    panel.Polyline(varied[2 * e + 1], color, 1.5, kDashed);
    legend.push_back({fmt::format("v{} (σ|v_ρ| ≤ {})", e + 1, Length(largest[e])), color});
  }
  legend.push_back({"+", palette::kBlack, Marker::kLine, {}, 1.5});
  legend.push_back({"−", palette::kBlack, Marker::kLine, kDashed, 1.5});
  legend.push_back({"MAP", palette::kGray, Marker::kLine, {}, 1.0});
  panel.LegendRow(legend);
}

// --- (d) prior vs posterior range standard deviation (Fig. 6d) -------------------------------

void DrawStdPanel(cairo_t* cr, const Rect& cell, const Inputs& in) {
  const priorlets::Posterior& post = in.posterior;
  const Scan& scan = in.scan;
  std::vector<Vec2> prior, posterior;
  std::vector<double> ratios;
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  if (post.computed) {
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const double x = RadToDeg(scan.angles[i]);
      prior.emplace_back(x, post.prior_std_rho[i]);
      posterior.emplace_back(x, post.posterior_std_rho[i]);
      for (double s : {post.prior_std_rho[i], post.posterior_std_rho[i]}) {
        if (std::isfinite(s) && s > 0.0) {
          lo = std::min(lo, s);
          hi = std::max(hi, s);
        }
      }
      if (post.posterior_std_rho[i] > 0.0 && std::isfinite(post.prior_std_rho[i]))
        ratios.push_back(post.prior_std_rho[i] / post.posterior_std_rho[i]);
    }
  }
  if (!(lo <= hi)) {  // nothing to draw
    lo = 1e-3;
    hi = 1e-1;
  }
  // At least a decade, centred on the data's geometric middle.
  const double middle = std::sqrt(lo * hi);
  lo = std::min(lo / 1.3, middle / std::sqrt(10.0));
  hi = std::max(hi * 1.3, middle * std::sqrt(10.0));
  std::string title = "(d) Range standard deviation, prior and posterior";
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(ratios.size() / 2),
                     ratios.end());
    title += fmt::format(" (median ratio {:.3g})", ratios[ratios.size() / 2]);
  }
  const double x_lo = RadToDeg(scan.angles.front()), x_hi = RadToDeg(scan.angles.back());
  const Panel panel(cr, cell, x_lo, std::max(x_hi, x_lo + 1e-6), lo, hi,
                    {.title = title,
                     .x_label = "beam angle φ (deg)",
                     .y_label = "σ_ρ (m)",
                     .log_y = true,
                     .legend_row = true});
  if (!post.computed) {
    panel.DrawNote("Posterior not computed: " + post.note);
    return;
  }
  panel.DrawFrame();
  panel.Polyline(prior, palette::kOrange, 3.0);  // wider: it shows where the two coincide
  panel.Polyline(posterior, palette::kBlue, 1.5);
  panel.LegendRow({{"prior (sensor noise)", palette::kOrange, Marker::kLine, {}, 3.0},
                   {"posterior (sqrt diag Σ_x)", palette::kBlue}});
}

// --- (e) posterior covariance of the in-model ranges (Fig. 6c) --------------------------------

// Averages over square blocks of `block` x `block` entries (partial blocks at the ends).
Eigen::MatrixXd BlockAverage(const Eigen::MatrixXd& m, Eigen::Index block) {
  const Eigen::Index n = (m.rows() + block - 1) / block;
  Eigen::MatrixXd out(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    for (Eigen::Index c = 0; c < n; ++c) {
      const Eigen::Index rows = std::min(block, m.rows() - r * block);
      const Eigen::Index cols = std::min(block, m.cols() - c * block);
      out(r, c) = m.block(r * block, c * block, rows, cols).mean();
    }
  }
  return out;
}

void DrawCovariancePanel(cairo_t* cr, const Rect& cell, const Inputs& in) {
  const Eigen::MatrixXd& cov = in.posterior.range_covariance;
  const Eigen::Index m = cov.rows();
  const Eigen::Index block = std::max<Eigen::Index>(
      1, (m + in.options.max_heat_map_cells - 1) / std::max(in.options.max_heat_map_cells, 1));
  std::string title = "(e) Posterior covariance of the in-model ranges";
  if (block > 1) title += fmt::format(" ({0}×{0} means)", block);
  const Panel panel(cr, cell, 0.0, std::max<double>(static_cast<double>(m), 1.0), 0.0,
                    std::max<double>(static_cast<double>(m), 1.0),
                    {.title = title,
                     .x_label = "in-model reading j",
                     .y_label = "in-model reading i",
                     .equal_aspect = true,
                     .invert_y = true,
                     .grid = false,
                     .right_margin_px = 110});
  if (!in.posterior.computed || m == 0) {
    panel.DrawNote(!in.posterior.computed
                       ? "Posterior not computed: " + in.posterior.note
                       : std::string("Range covariance not kept "
                                     "(PosteriorOptions::keep_range_covariance)."));
    return;
  }
  PRIORMAP_CHECK(cov.cols() == m && static_cast<std::size_t>(m) == in.map.inmodel_beams.size(),
                 "the range covariance is m x m, m the in-model readings");
  // Square metres are tiny numbers: the first of m², cm², mm² that shows the largest as >= 1.
  const double largest = cov.cwiseAbs().maxCoeff();
  const auto [scale, unit] = largest >= 1.0    ? std::pair(1.0, "m²")
                             : largest >= 1e-4 ? std::pair(1e4, "cm²")
                                               : std::pair(1e6, "mm²");
  const Eigen::MatrixXd cells = BlockAverage(cov, block) * scale;
  double vmin = cells.minCoeff(), vmax = cells.maxCoeff();
  if (!(vmin < vmax)) {  // a constant matrix: any range around it
    vmin -= 1.0;
    vmax += 1.0;
  }
  panel.Image(cells, Colormap::kViridis, vmin, vmax);  // cells span the whole plot
  panel.DrawFrame();
  // Region and surface borders as thin lines between the readings they separate.
  for (std::size_t j = 0; j < in.map.links.size(); ++j) {
    if (in.map.links[j] == Link::kSameRegion) continue;
    const double at = static_cast<double>(j + 1);
    const Color color = palette::kWhite.WithAlpha(0.7);
    panel.Segment({at, 0.0}, {at, static_cast<double>(m)}, color, 0.8, kDashed);
    panel.Segment({0.0, at}, {static_cast<double>(m), at}, color, 0.8, kDashed);
  }
  panel.ColorBar(Colormap::kViridis, vmin, vmax, fmt::format("cov(ρ_i, ρ_j) ({})", unit));
}

// --- summary --------------------------------------------------------------------------------

std::vector<std::string> SummaryLines(const Inputs& in) {
  const Scan& scan = in.scan;
  const priorlets::MapScan& map = in.map;
  const std::size_t valid = scan.NumValid(), inmodel = map.inmodel_beams.size();
  std::vector<std::string> lines{
      fmt::format("{} beams, {} valid, {} in model, {} outliers", scan.size(), valid, inmodel,
                  valid - std::min(valid, inmodel)),
      fmt::format("{}, {}{}", Plural(map.regions.size(), "region"),
                  Plural(map.surfaces.size(), "surface"),
                  map.closed ? " (a full turn: the last reading borders the first)" : ""),
      fmt::format("{}, largest constraint residual {:.2g}",
                  map.feasible ? "feasible" : "NOT feasible", map.max_violation),
      fmt::format("objective {:.6g}; {} outer rounds, {} Newton steps, {:.0f} ms", map.objective,
                  map.stats.outer_rounds, map.stats.newton_steps, map.stats.seconds_total * 1e3)};
  if (scan.truth) {
    double alpha_sum = 0.0, measured_sq = 0.0, corrected_sq = 0.0;
    std::size_t n = 0;
    for (std::size_t i : map.inmodel_beams) {
      if (!std::isfinite(scan.truth->range[i]) || scan.truth->outlier[i] != 0) continue;
      alpha_sum += std::abs(WrapAngle(map.alpha[i] - scan.truth->alpha[i]));
      measured_sq += std::pow(scan.ranges[i] - scan.truth->range[i], 2);
      corrected_sq += std::pow(map.rho[i] - scan.truth->range[i], 2);
      ++n;
    }
    if (n > 0) {
      const double count = static_cast<double>(n);
      lines.push_back(
          fmt::format("vs ground truth: mean |α error| {:.2f}°", RadToDeg(alpha_sum) / count));
      lines.push_back(fmt::format("  range RMS error {} measured, {} corrected",
                                  Length(std::sqrt(measured_sq / count)),
                                  Length(std::sqrt(corrected_sq / count))));
    }
  }
  const priorlets::Posterior& post = in.posterior;
  lines.push_back(fmt::format("degrees of freedom: Free {}, Extr {}, Intr {}", post.dof.free,
                              post.dof.extrinsic, post.dof.intrinsic));
  lines.push_back(
      post.dof.pose_independent
          ? std::string("pose-independent (Extr inside Free)")
          : fmt::format("NOT pose-independent (min cosine {:.4f})", post.dof.min_extrinsic_cosine));
  if (post.computed) {
    lines.push_back(fmt::format(
        "covariance: {}, {:.0f} ms",
        post.form == priorlets::CovarianceForm::kConditional ? "conditional" : "projected",
        post.seconds * 1e3));
  }
  if (!post.note.empty()) {
    for (const std::string& line : detail::WrapText("note: " + post.note, 70))
      lines.push_back(line);
  }
  return lines;
}

void DrawSummary(cairo_t* cr, const Rect& cell, const Inputs& in) {
  cairo_save(cr);
  detail::SetColor(cr, palette::kBlack);
  const double x = cell.x + 70;
  double y = cell.y + 8;
  detail::DrawText(cr, "Summary", x, y, 13.0, 0.0, 0.0, true);
  y += 30;
  for (const std::string& line : SummaryLines(in)) {
    if (y > cell.y + cell.height - 10) break;
    detail::DrawText(cr, line, x, y, 12.0, 0.0, 0.0);
    y += 20;
  }
  cairo_restore(cr);
}

}  // namespace

struct MapScanFigure::Impl {
  std::unique_ptr<detail::Canvas> canvas;
};

MapScanFigure::MapScanFigure(const Scan& scan, const priorlets::MapScan& map,
                             const priorlets::Posterior& posterior,
                             const MapScanFigureOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const std::size_t n = scan.size();
  PRIORMAP_CHECK(n > 0 && map.rho.size() == n && map.alpha.size() == n &&
                     map.initial_alpha.size() == n && map.alpha_lower.size() == n &&
                     map.alpha_upper.size() == n && map.inmodel.size() == n &&
                     map.links.size() + std::min<std::size_t>(map.inmodel_beams.size(), 1) ==
                         map.inmodel_beams.size(),
                 "the MAP scan does not belong to the scan");
  PRIORMAP_CHECK(!posterior.computed || (posterior.prior_std_rho.size() == n &&
                                         posterior.posterior_std_rho.size() == n),
                 "the posterior does not belong to the scan");
  for (const priorlets::Eigenvariation& e : posterior.intrinsic_eigenvariations)
    PRIORMAP_CHECK(e.rho.size() == n, "an eigenvariation has one entry per beam");

  // Widths below 600 px grow to it; a negative one is a caller's mistake.
  detail::CheckPixels(options.width_px, "a MAP-scan figure's width_px");
  const Inputs in{scan, map, posterior, options, SensorFrameBounds(scan, map)};
  const double width = std::max(options.width_px, 600);
  const double title_height = options.title.empty() ? 0.0 : 40.0;
  const double half = width / 2;
  const double row1 = std::round(0.50 * width), row2 = std::round(0.30 * width),
               row3 = std::round(0.40 * width);
  impl_->canvas =
      std::make_unique<detail::Canvas>(width, std::ceil(title_height + row1 + row2 + row3));
  cairo_t* cr = impl_->canvas->cr();
  if (!options.title.empty()) {
    detail::SetColor(cr, palette::kBlack);
    detail::DrawText(cr, options.title, half, 12, 16.0, 0.5, 0.0, true);
  }
  double y = title_height;
  DrawScanPanel(cr, {0, y, half, row1}, in);
  DrawEigenvariationPanel(cr, {half, y, half, row1}, in);
  y += row1;
  DrawNormalPanel(cr, {0, y, half, row2}, in);
  DrawStdPanel(cr, {half, y, half, row2}, in);
  y += row2;
  DrawCovariancePanel(cr, {0, y, half, row3}, in);
  DrawSummary(cr, {half, y + 20, half, row3 - 20}, in);
}

MapScanFigure::~MapScanFigure() = default;
MapScanFigure::MapScanFigure(MapScanFigure&&) noexcept = default;
MapScanFigure& MapScanFigure::operator=(MapScanFigure&&) noexcept = default;

void MapScanFigure::Save(const std::filesystem::path& path) const {
  impl_->canvas->Save(path);
}

int MapScanFigure::width_px() const {
  return static_cast<int>(impl_->canvas->width());
}
int MapScanFigure::height_px() const {
  return static_cast<int>(impl_->canvas->height());
}

}  // namespace priormap::render
