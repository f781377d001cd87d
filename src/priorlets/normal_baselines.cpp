#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <variant>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

namespace priormap::priorlets {
namespace detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Hessian normal form: p . (cos alpha_out, sin alpha_out) = rho, rho >= 0 (normal pointing away
// from the sensor, the form in which a straight wall has one parameter pair for all its beams).
struct Line {
  double alpha_out = 0.0;
  double rho = 0.0;
};

// Weighted total least squares: the normal is the minor axis of the weighted scatter matrix.
std::optional<Line> FitOrthogonal(const Scan& scan, std::span<const std::size_t> beams) {
  double sw = 0.0;
  Vec2 centroid = Vec2::Zero();
  for (std::size_t i : beams) {
    const double w = 1.0 / (scan.sigma[i] * scan.sigma[i]);
    sw += w;
    centroid += w * scan.PointInSensorFrame(i);
  }
  centroid /= sw;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t i : beams) {
    const double w = 1.0 / (scan.sigma[i] * scan.sigma[i]);
    const Vec2 d = scan.PointInSensorFrame(i) - centroid;
    sxx += w * d.x() * d.x();
    sxy += w * d.x() * d.y();
    syy += w * d.y() * d.y();
  }
  if (!(sxx + syy > 0.0)) return std::nullopt;  // all points coincide
  Line line{0.5 * std::atan2(2.0 * sxy, sxx - syy) + kPi / 2, 0.0};
  line.rho = UnitVector(line.alpha_out).dot(centroid);
  if (line.rho < 0.0) {
    line.alpha_out += kPi;
    line.rho = -line.rho;
  }
  return line;
}

// Gauss-Newton on the range residuals e_i = r_i - rho / cos(phi_i - alpha_out), from the
// orthogonal fit. Returns the last line that lowered the cost; stops when a beam does not meet
// the line in front of the sensor (the model is undefined there).
Line RefineRadial(const Scan& scan, std::span<const std::size_t> beams, Line line) {
  constexpr int kMaxIterations = 20;
  constexpr double kMinCos = 1e-6;
  Line accepted = line;
  double accepted_cost = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Mat2 h = Mat2::Zero();
    Vec2 g = Vec2::Zero();
    double cost = 0.0;
    for (std::size_t i : beams) {
      const double x = scan.angles[i] - line.alpha_out;
      const double c = std::cos(x);
      if (c < kMinCos) return accepted;
      const double w = 1.0 / (scan.sigma[i] * scan.sigma[i]);
      const double e = scan.ranges[i] - line.rho / c;
      const Row2 J_range_line(-line.rho * std::sin(x) / (c * c), 1.0 / c);
      h += w * J_range_line.transpose() * J_range_line;
      g += w * J_range_line.transpose() * e;
      cost += w * e * e;
    }
    if (!(cost < accepted_cost)) return accepted;
    accepted = line;
    accepted_cost = cost;
    const Vec2 step = h.ldlt().solve(g);
    if (!step.allFinite()) return accepted;
    line.alpha_out += step.x();
    line.rho += step.y();
    if (step.norm() < 1e-13 * (1.0 + line.rho)) return line;
  }
  return accepted;
}

std::optional<Line> FitLine(const Scan& scan, std::span<const std::size_t> beams,
                            LineFitModel model) {
  if (beams.size() < 2) return std::nullopt;
  std::optional<Line> line = FitOrthogonal(scan, beams);
  if (line && model == LineFitModel::kRadial) line = RefineRadial(scan, beams, *line);
  return line;
}

// The representative of the line's normal that points back along beam i, wrapped as truth.alpha.
double NormalTowardsSensor(const Line& line, double phi) {
  const double towards =
      std::cos(phi - line.alpha_out) >= 0.0 ? line.alpha_out + kPi : line.alpha_out;
  return WrapAngle(towards);
}

// Valid beams of the window around `centre`, walking outwards and stopping at the first jump.
void CollectWindow(const Scan& scan, std::size_t centre, int half, double max_jump,
                   std::vector<std::size_t>& beams) {
  beams.assign(1, centre);
  for (const int direction : {-1, +1}) {
    std::size_t last = centre;
    for (int offset = 1; offset <= half; ++offset) {
      const auto j = static_cast<std::ptrdiff_t>(centre) + direction * offset;
      if (j < 0 || j >= static_cast<std::ptrdiff_t>(scan.size())) break;
      const auto u = static_cast<std::size_t>(j);
      if (!scan.IsValid(u)) continue;
      if ((scan.PointInSensorFrame(u) - scan.PointInSensorFrame(last)).norm() > max_jump) break;
      beams.push_back(u);
      last = u;
    }
  }
}

}  // namespace
}  // namespace detail

const char* ToString(LineFitModel model) {
  switch (model) {
    case LineFitModel::kOrthogonal:
      return "orthogonal";
    case LineFitModel::kRadial:
      return "radial";
  }
  return "unknown";
}

bool PcaNormalOptions::IsValid(std::string* why) const {
  std::string reason;
  if (k < 3 || k % 2 == 0) {
    reason = fmt::format("k must be odd and at least 3 (got {})", k);
  } else if (!(max_neighbour_distance > 0.0)) {
    reason =
        fmt::format("max_neighbour_distance must be positive (got {})", max_neighbour_distance);
  }
  if (why) *why = reason;
  return reason.empty();
}

std::optional<double> FitLineNormal(const Scan& scan, std::span<const std::size_t> beams,
                                    std::size_t facing_beam, LineFitModel model) {
  const auto line = detail::FitLine(scan, beams, model);
  if (!line) return std::nullopt;
  return detail::NormalTowardsSensor(*line, scan.angles[facing_beam]);
}

std::vector<double> PcaNormals(const Scan& scan, const PcaNormalOptions& options) {
  std::string why;
  PRIORMAP_CHECK(options.IsValid(&why), why);
  std::vector<double> alpha(scan.size(), detail::kNaN);
  std::vector<std::size_t> beams;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    detail::CollectWindow(scan, i, options.k / 2, options.max_neighbour_distance, beams);
    alpha[i] = FitLineNormal(scan, beams, i, options.model).value_or(detail::kNaN);
  }
  return alpha;
}

LineFitResult OracleLineFitNormals(const Scan& scan, std::span<const int> labels,
                                   const OracleLineFitOptions& options) {
  PRIORMAP_CHECK(labels.size() == scan.size(),
                 fmt::format("{} labels for {} beams", labels.size(), scan.size()));
  std::map<int, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i) && labels[i] >= 0) groups[labels[i]].push_back(i);
  }
  LineFitResult result;
  result.alpha.assign(scan.size(), detail::kNaN);
  result.rho.assign(scan.size(), detail::kNaN);
  result.range.assign(scan.size(), detail::kNaN);
  for (const auto& [label, beams] : groups) {
    const auto line = detail::FitLine(scan, beams, options.model);
    if (!line) continue;
    for (std::size_t i : beams) {
      result.alpha[i] = detail::NormalTowardsSensor(*line, scan.angles[i]);
      result.rho[i] = line->rho;
      const double c = std::cos(scan.angles[i] - line->alpha_out);
      if (c > 0.0) result.range[i] = line->rho / c;
    }
  }
  return result;
}

std::vector<int> StraightRegionLabels(const Scan& scan, const Scene& scene) {
  PRIORMAP_CHECK(scan.truth.has_value(), "StraightRegionLabels needs a simulated scan");
  const ScanTruth& truth = *scan.truth;
  const std::vector<ScenePrimitive> primitives = scene.Primitives();
  std::vector<int> labels(scan.size(), -1);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const int region = truth.region[i];
    if (region < 0 || truth.outlier[i] != 0) continue;
    PRIORMAP_CHECK(static_cast<std::size_t>(region) < primitives.size(),
                   fmt::format("region {} is not in scene '{}'", region, scene.name));
    if (std::holds_alternative<Segment>(primitives[static_cast<std::size_t>(region)].shape)) {
      labels[i] = region;
    }
  }
  return labels;
}

NormalErrorStats CompareNormals(std::span<const double> estimate, std::span<const double> truth,
                                std::span<const std::uint8_t> mask) {
  PRIORMAP_CHECK(estimate.size() == truth.size(),
                 fmt::format("{} estimates for {} truths", estimate.size(), truth.size()));
  PRIORMAP_CHECK(mask.empty() || mask.size() == truth.size(), "mask size differs");
  NormalErrorStats stats;
  double sum = 0.0, max = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!std::isfinite(estimate[i]) || !std::isfinite(truth[i])) continue;
    if (!mask.empty() && mask[i] == 0) continue;
    const double error = std::abs(AngleDifference(estimate[i], truth[i]));
    sum += error;
    max = std::max(max, error);
    ++stats.count;
  }
  stats.mean_deg =
      stats.count > 0 ? RadToDeg(sum / static_cast<double>(stats.count)) : detail::kNaN;
  stats.max_deg = stats.count > 0 ? RadToDeg(max) : detail::kNaN;
  return stats;
}

}  // namespace priormap::priorlets
