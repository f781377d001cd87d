// The figures of prior-map SLAM (Parsley & Julier, Sec. VI, Figs. 4-5): plots over time as panels
// of one canvas, maps on a render::Figure.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/render/slam_figures.hpp>

#include "canvas.hpp"
#include "plot_panel.hpp"

namespace priormap::render {
namespace {

using detail::LegendEntry;
using detail::Marker;
using detail::Panel;
using detail::Rect;
using slam::RunTrace;
using slam::StudyResult;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const Color kWithPrior = palette::kBlue;
const Color kWithoutPrior = palette::kVermillion;
const Color kSpurious{0.85, 0.1, 0.1};
const Color kPriorSegment = palette::kSkyBlue;
const std::vector<double> kDashed{6.0, 4.0};
const std::vector<double> kDotted{1.5, 3.0};

// --- statistics over runs, per frame ------------------------------------------------------------

// The mean over runs of value(run, frame) at each frame, NaN where no run has a finite value.
template <typename Value>
std::vector<double> MeanOverRuns(const std::vector<RunTrace>& runs, std::size_t frames,
                                 const Value& value) {
  std::vector<double> out(frames, kNaN);
  for (std::size_t f = 0; f < frames; ++f) {
    double sum = 0.0;
    int count = 0;
    for (const RunTrace& run : runs) {
      if (f >= run.nees.size()) continue;  // every trace has one entry per frame
      const double v = value(run, f);
      if (!std::isfinite(v)) continue;
      sum += v;
      ++count;
    }
    if (count > 0) out[f] = sum / count;
  }
  return out;
}

// sqrt(mean over runs of value(run, frame)^2) at each frame; NaN where no run has a finite value.
template <typename Value>
std::vector<double> RmsOverRuns(const std::vector<RunTrace>& runs, std::size_t frames,
                                const Value& value) {
  std::vector<double> out = MeanOverRuns(runs, frames, [&](const RunTrace& run, std::size_t f) {
    const double v = value(run, f);
    return v * v;
  });
  for (double& x : out) x = std::sqrt(x);
  return out;
}

std::vector<Vec2> Curve(const std::vector<double>& x, const std::vector<double>& y,
                        double scale = 1.0) {
  std::vector<Vec2> points;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    points.emplace_back(x[i], y[i] * scale);
  return points;
}

// Zero becomes a missing value (log axes; Fig. 5 leaves zero counts out).
std::vector<double> PositiveOrNaN(std::vector<double> values) {
  for (double& v : values) {
    if (!(v > 0.0)) v = kNaN;
  }
  return values;
}

std::pair<double, double> TimeRange(const StudyResult& study) {
  if (study.times.empty()) return {0.0, 1.0};
  const double lo = study.times.front(), hi = study.times.back();
  return hi > lo ? std::pair(lo, hi) : std::pair(lo - 0.5, lo + 0.5);
}

// [0, largest finite value] with a little room above (linear axes of non-negative values).
double UpperLimit(const std::vector<std::vector<Vec2>>& curves) {
  double hi = 0.0;
  for (const std::vector<Vec2>& curve : curves) {
    for (const Vec2& p : curve) {
      if (std::isfinite(p.y())) hi = std::max(hi, p.y());
    }
  }
  return hi > 0.0 ? 1.05 * hi : 1.0;
}

// A log-axis range around the positive finite values (and `extra`), at least a decade wide.
std::pair<double, double> LogRange(const std::vector<std::vector<double>>& series,
                                   std::initializer_list<double> extra = {}) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  const auto add = [&](double v) {
    if (std::isfinite(v) && v > 0.0) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  };
  for (const std::vector<double>& s : series) std::for_each(s.begin(), s.end(), add);
  std::for_each(extra.begin(), extra.end(), add);
  if (!(lo <= hi)) return {0.1, 10.0};
  const double middle = std::sqrt(lo * hi);
  return {std::min(lo / 1.5, middle / std::sqrt(10.0)),
          std::max(hi * 1.5, middle * std::sqrt(10.0))};
}

// --- the plots ----------------------------------------------------------------------------------

// Fig. 4, one panel per pose component.
void DrawPoseErrorPanel(cairo_t* cr, const Rect& cell, const StudyResult& study, int k,
                        bool legend) {
  static const char* const kNames[3] = {"x", "y", "θ"};
  const double scale = k == 2 ? RadToDeg(1.0) : 1.0;
  const std::size_t frames = study.times.size();
  const auto curves = [&](const std::vector<RunTrace>& runs) {
    const std::vector<double> error = RmsOverRuns(
        runs, frames, [k](const RunTrace& run, std::size_t f) { return run.error[f][k]; });
    const std::vector<double> sigma = RmsOverRuns(
        runs, frames, [k](const RunTrace& run, std::size_t f) { return run.sigma[f][k]; });
    return std::pair(Curve(study.times, error, scale), Curve(study.times, sigma, 3.0 * scale));
  };
  const auto [with_error, with_bound] = curves(study.with_prior);
  const auto [without_error, without_bound] = curves(study.without_prior);
  const auto [t_lo, t_hi] = TimeRange(study);
  const Panel panel(cr, cell, t_lo, t_hi, 0.0,
                    UpperLimit({with_error, with_bound, without_error, without_bound}),
                    {.title = fmt::format("{} error: RMS over {} runs and 3σ bound", kNames[k],
                                          study.with_prior.size()),
                     .x_label = "time (s)",
                     .y_label = k == 2 ? "θ error (deg)" : fmt::format("{} error (m)", kNames[k]),
                     .legend_row = legend});
  panel.DrawFrame();
  panel.Polyline(without_bound, kWithoutPrior, 1.5, kDashed);
  panel.Polyline(without_error, kWithoutPrior, 1.5);
  panel.Polyline(with_bound, kWithPrior, 1.5, kDashed);
  panel.Polyline(with_error, kWithPrior, 1.5);
  if (legend) {
    panel.LegendRow({{"RMS error, with prior map", kWithPrior},
                     {"3σ, with prior map", kWithPrior, Marker::kLine, kDashed, 1.5},
                     {"RMS error, without", kWithoutPrior},
                     {"3σ, without", kWithoutPrior, Marker::kLine, kDashed, 1.5}});
  }
}

void DrawNeesPanel(cairo_t* cr, const Rect& cell, const StudyResult& study) {
  const std::size_t frames = study.times.size();
  const auto nees = [](const RunTrace& run, std::size_t f) { return run.nees[f]; };
  const std::vector<double> with = MeanOverRuns(study.with_prior, frames, nees);
  const std::vector<double> without = MeanOverRuns(study.without_prior, frames, nees);
  const auto [lo, hi] = LogRange({with, without}, {study.nees_band_low, study.nees_band_high});
  const auto [t_lo, t_hi] = TimeRange(study);
  const Panel panel(
      cr, cell, t_lo, t_hi, lo, hi,
      {.title = fmt::format("NEES averaged over {} runs, 95 % band [{:.2f}, {:.2f}]",
                            study.with_prior.size(), study.nees_band_low, study.nees_band_high),
       .x_label = "time (s)",
       .y_label = "average NEES",
       .log_y = true,
       .legend_row = true});
  panel.DrawFrame();
  for (const double band : {study.nees_band_low, study.nees_band_high}) {
    if (band > 0.0) panel.Segment({t_lo, band}, {t_hi, band}, palette::kBlack, 1.2, kDashed);
  }
  panel.Polyline(Curve(study.times, without), kWithoutPrior, 1.5);
  panel.Polyline(Curve(study.times, with), kWithPrior, 1.5);
  panel.LegendRow({{"with prior map", kWithPrior},
                   {"without prior map", kWithoutPrior},
                   {"95 % band", palette::kBlack, Marker::kLine, kDashed, 1.2}});
}

void DrawRelationsPanel(cairo_t* cr, const Rect& cell, const StudyResult& study) {
  const std::size_t frames = study.times.size();
  const auto mean = [&](auto count) {
    return PositiveOrNaN(
        MeanOverRuns(study.with_prior, frames, [&](const RunTrace& run, std::size_t f) {
          return f < run.result.frames.size() ? static_cast<double>(count(run.result.frames[f]))
                                              : kNaN;
        }));
  };
  const std::vector<double> correct =
      mean([](const slam::FrameRecord& r) { return r.relations_correct; });
  const std::vector<double> incorrect =
      mean([](const slam::FrameRecord& r) { return r.relations_incorrect; });
  const std::vector<double> spurious =
      mean([](const slam::FrameRecord& r) { return r.relations_spurious; });
  const auto [lo, hi] = LogRange({correct, incorrect, spurious});
  const auto [t_lo, t_hi] = TimeRange(study);
  const Panel panel(
      cr, cell, t_lo, t_hi, lo, hi,
      {.title = fmt::format("Relations applied to landmarks in the state, mean over {} runs "
                            "(gaps: none)",
                            study.with_prior.size()),
       .x_label = "time (s)",
       .y_label = "relations (log scale)",
       .log_y = true,
       .legend_row = true});
  panel.DrawFrame();
  panel.Polyline(Curve(study.times, correct), palette::kGreen, 1.2);
  panel.Polyline(Curve(study.times, incorrect), palette::kVermillion, 3.5);
  // Black on top: these are a subset of the incorrect ones, whose thick line they often cover.
  panel.Polyline(Curve(study.times, spurious), palette::kBlack, 1.5, kDotted);
  panel.LegendRow({{"applied correctly", palette::kGreen, Marker::kLine, {}, 1.2},
                   {"incorrectly", palette::kVermillion, Marker::kLine, {}, 3.5},
                   {"to spurious segments", palette::kBlack, Marker::kLine, kDotted, 1.5}});
}

// --- maps ---------------------------------------------------------------------------------------

std::vector<Vec2> EstimatedPath(const slam::SlamResult& result) {
  std::vector<Vec2> path;
  for (const slam::FrameRecord& frame : result.frames) path.push_back(frame.estimate.translation());
  return path;
}

void Extend(Box2& box, const std::vector<Vec2>& points) {
  for (const Vec2& p : points) {
    if (p.allFinite()) box.extend(p);
  }
}

Box2 NonEmpty(Box2 box) {
  if (box.isEmpty()) return {Vec2(-1.0, -1.0), Vec2(1.0, 1.0)};
  const double pad = 0.02 * std::max(box.sizes().maxCoeff(), 1.0);
  return {box.min() - Vec2::Constant(pad), box.max() + Vec2::Constant(pad)};
}

bool PositiveDefinite(const Mat2& covariance) {
  const Eigen::LLT<Mat2> llt(covariance);
  return covariance.allFinite() && llt.info() == Eigen::Success && covariance.determinant() > 0.0;
}

// The point of segment (a, b) nearest to p.
Vec2 NearestOnSegment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double t =
      d.squaredNorm() > 0.0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return a + t * d;
}

}  // namespace

// --- StudyPlot ----------------------------------------------------------------------------------

struct StudyPlot::Impl {
  std::unique_ptr<detail::Canvas> canvas;
};

StudyPlot::StudyPlot(const StudyResult& study, StudyPlotKind kind, const StudyPlotOptions& options)
    : impl_(std::make_unique<Impl>()) {
  for (const std::vector<RunTrace>* runs : {&study.with_prior, &study.without_prior}) {
    for (const RunTrace& run : *runs) {
      PRIORMAP_CHECK(run.error.size() == study.times.size() &&
                         run.sigma.size() == study.times.size() &&
                         run.nees.size() == study.times.size(),
                     "every run trace has one entry per frame of the study");
    }
  }
  // Widths below 500 px grow to it; a negative one is a caller's mistake.
  detail::CheckPixels(options.width_px, "a study plot's width_px");
  const double width = std::max(options.width_px, 500);
  const double title_height = options.title.empty() ? 0.0 : 40.0;
  const int panels = kind == StudyPlotKind::kPoseError ? 3 : 1;
  const double panel_height = std::round((panels == 3 ? 0.3 : 0.5) * width);
  const double legend_height = 24.0;
  impl_->canvas = std::make_unique<detail::Canvas>(
      width, std::ceil(title_height + panels * panel_height + legend_height));
  cairo_t* cr = impl_->canvas->cr();
  if (!options.title.empty()) {
    detail::SetColor(cr, palette::kBlack);
    detail::DrawText(cr, options.title, width / 2, 12, 16.0, 0.5, 0.0, true);
  }
  switch (kind) {
    case StudyPlotKind::kPoseError:
      for (int k = 0; k < 3; ++k) {
        const double y = title_height + k * panel_height;
        const bool last = k == 2;
        DrawPoseErrorPanel(cr, {0, y, width, panel_height + (last ? legend_height : 0.0)}, study, k,
                           last);
      }
      break;
    case StudyPlotKind::kNees:
      DrawNeesPanel(cr, {0, title_height, width, panel_height + legend_height}, study);
      break;
    case StudyPlotKind::kRelations:
      DrawRelationsPanel(cr, {0, title_height, width, panel_height + legend_height}, study);
      break;
  }
}

StudyPlot::~StudyPlot() = default;
StudyPlot::StudyPlot(StudyPlot&&) noexcept = default;
StudyPlot& StudyPlot::operator=(StudyPlot&&) noexcept = default;

void StudyPlot::Save(const std::filesystem::path& path) const {
  impl_->canvas->Save(path);
}

int StudyPlot::width_px() const {
  return static_cast<int>(impl_->canvas->width());
}
int StudyPlot::height_px() const {
  return static_cast<int>(impl_->canvas->height());
}

// --- maps ---------------------------------------------------------------------------------------

Figure StudyMapFigure(const slam::UrbanWorld& world, const slam::UrbanRun& run,
                      const RunTrace* with_prior, const RunTrace* without_prior,
                      const SlamMapOptions& options) {
  std::vector<Vec2> truth;
  for (const Se2& pose : world.poses) truth.push_back(pose.translation());
  const std::vector<Vec2> with_path =
      with_prior ? EstimatedPath(with_prior->result) : std::vector<Vec2>();
  const std::vector<Vec2> without_path =
      without_prior ? EstimatedPath(without_prior->result) : std::vector<Vec2>();
  Box2 bounds;
  for (const Polygon& building : world.buildings) bounds.extend(building.Bounds());
  for (const slam::PriorSegment& s : run.prior_map.segments) Extend(bounds, {s.a, s.b});
  Extend(bounds, truth);
  Extend(bounds, with_path);
  Extend(bounds, without_path);

  Figure figure(NonEmpty(bounds), {.width_px = options.width_px,
                                   .max_height_px = options.width_px,
                                   .title = options.title,
                                   .padding_m = 0.0});
  for (const Polygon& building : world.buildings)
    figure.FilledPolygon(building, palette::kLightGray, {palette::kGray, 1.0, {}});
  std::size_t spurious = 0;
  for (std::size_t i = 0; i < run.prior_map.segments.size(); ++i) {
    const slam::PriorSegment& s = run.prior_map.segments[i];
    const bool is_spurious = i < run.segment_wall.size() && run.segment_wall[i] < 0;
    spurious += is_spurious ? 1 : 0;
    figure.Line(s.a, s.b, {is_spurious ? kSpurious : kPriorSegment, is_spurious ? 2.0 : 1.5, {}});
  }
  std::vector<Vec2> on_wall, off_wall;
  for (const slam::Beacon& beacon : world.beacons)
    (beacon.on_wall ? on_wall : off_wall).push_back(beacon.position);
  figure.Points(on_wall, palette::kGreen, 2.0);
  figure.Points(off_wall, palette::kOrange, 2.0);
  figure.Polyline(truth, false, {palette::kBlack, 1.2, {}});
  // Wider, under the other: where the two estimates agree, both stay visible.
  if (!without_path.empty()) figure.Polyline(without_path, false, {palette::kPurple, 3.5, {}});
  if (!with_path.empty()) figure.Polyline(with_path, false, {kWithPrior, 1.5, {}});
  if (!world.poses.empty()) figure.PoseMarker(world.poses.front(), palette::kYellow, 12.0);

  figure.AddLegend("buildings", palette::kGray);
  figure.AddLegend("prior map", kPriorSegment);
  figure.AddLegend(fmt::format("spurious ({})", spurious), kSpurious);
  figure.AddLegend(fmt::format("beacons on walls ({})", on_wall.size()), palette::kGreen);
  figure.AddLegend(fmt::format("off ({})", off_wall.size()), palette::kOrange);
  figure.AddLegend("truth", palette::kBlack);
  if (!with_path.empty()) figure.AddLegend("with prior", kWithPrior);
  if (!without_path.empty()) figure.AddLegend("without", palette::kPurple);
  return figure;
}

Figure SlamRunMapFigure(const slam::SlamResult& result, const slam::PriorMap* prior_map,
                        const SlamMapOptions& options) {
  const std::vector<Vec2> path = EstimatedPath(result);
  Box2 bounds;
  Extend(bounds, path);
  if (prior_map) {
    for (const slam::PriorSegment& s : prior_map->segments) Extend(bounds, {s.a, s.b});
  }
  for (const slam::LandmarkEstimate& l : result.landmarks) Extend(bounds, {l.position});
  for (const slam::SegmentEstimate& s : result.segments) Extend(bounds, {s.a, s.b});

  Figure figure(NonEmpty(bounds), {.width_px = options.width_px,
                                   .max_height_px = options.width_px,
                                   .title = options.title,
                                   .padding_m = 0.0});
  if (prior_map) {
    for (const slam::PriorSegment& s : prior_map->segments)
      figure.Line(s.a, s.b, {kPriorSegment, 1.5, {}});
  }
  for (const slam::SegmentEstimate& s : result.segments)
    figure.Line(s.a, s.b, {palette::kPurple, 2.5, {}});
  // Relations whose landmark and segment are both still in the state.
  std::size_t drawn_relations = 0, drawn_flagged = 0;
  for (const slam::RelationRecord& r : result.relations) {
    const auto landmark =
        std::find_if(result.landmarks.begin(), result.landmarks.end(),
                     [&](const slam::LandmarkEstimate& l) { return l.id == r.landmark; });
    const auto segment =
        std::find_if(result.segments.begin(), result.segments.end(),
                     [&](const slam::SegmentEstimate& s) { return s.segment == r.segment; });
    if (landmark == result.landmarks.end() || segment == result.segments.end()) continue;
    figure.Line(landmark->position, NearestOnSegment(landmark->position, segment->a, segment->b),
                {r.flagged ? kSpurious : palette::kGray, 1.0, {}});
    ++(r.flagged ? drawn_flagged : drawn_relations);
  }
  std::vector<Vec2> landmarks;
  for (const slam::LandmarkEstimate& l : result.landmarks) {
    landmarks.push_back(l.position);
    if (PositiveDefinite(l.covariance))
      figure.CovarianceEllipse(l.position, l.covariance, 3.0, {palette::kGreen, 1.0, {}});
  }
  figure.Points(landmarks, palette::kGreen, 2.0);
  figure.Polyline(path, false, {kWithPrior, 1.5, {}});
  if (!result.frames.empty()) {
    figure.PoseMarker(result.frames.front().estimate, palette::kYellow, 12.0);
    figure.PoseMarker(result.frames.back().estimate, kWithPrior, 12.0);
  }
  if (prior_map) figure.AddLegend("prior map", kPriorSegment);
  figure.AddLegend(fmt::format("segments in the state ({})", result.segments.size()),
                   palette::kPurple);
  figure.AddLegend(fmt::format("landmarks with 3σ ({})", result.landmarks.size()), palette::kGreen);
  if (drawn_relations > 0) figure.AddLegend("relations", palette::kGray);
  if (drawn_flagged > 0) figure.AddLegend("flagged relations", kSpurious);
  figure.AddLegend("estimated path", kWithPrior);
  return figure;
}

}  // namespace priormap::render
