#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include <priormap/core/angles.hpp>
#include <priormap/priorlets/line_segments.hpp>

namespace priormap::priorlets {
namespace {

struct LineFit {
  double radius = 0.0;
  double angle = 0.0;
  Vec2 normal = Vec2::UnitX();
  double rms = 0.0;
};

// Total least squares: the line through the centroid along the scatter's main axis.
LineFit FitLine(const std::vector<double>& ranges, const std::vector<double>& bearings) {
  const auto n = static_cast<double>(ranges.size());
  Vec2 centroid = Vec2::Zero();
  for (std::size_t i = 0; i < ranges.size(); ++i)
    centroid += ranges[i] * Vec2(std::cos(bearings[i]), std::sin(bearings[i]));
  centroid /= n;
  Mat2 scatter = Mat2::Zero();
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const Vec2 d = ranges[i] * Vec2(std::cos(bearings[i]), std::sin(bearings[i])) - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Mat2> eigen(scatter);
  LineFit fit;
  fit.normal = eigen.eigenvectors().col(0);  // the smallest spread: across the line
  fit.radius = fit.normal.dot(centroid);
  if (fit.radius < 0.0) {
    fit.radius = -fit.radius;
    fit.normal = -fit.normal;
  }
  fit.angle = std::atan2(fit.normal.y(), fit.normal.x());
  fit.rms = std::sqrt(std::max(0.0, eigen.eigenvalues()(0)) / n);
  return fit;
}

Vec2 Project(const LineFit& fit, const Vec2& p) {
  return p - (fit.normal.dot(p) - fit.radius) * fit.normal;
}

}  // namespace

LineSegments ExtractLineSegments(const Scan& scan, const MapScan& map, const Posterior* posterior,
                                 const LineSegmentOptions& options) {
  LineSegments out;
  const bool full =
      posterior != nullptr && posterior->computed &&
      posterior->range_covariance.rows() == static_cast<Eigen::Index>(map.inmodel_beams.size());
  const bool diagonal = !full && posterior != nullptr && posterior->computed &&
                        posterior->posterior_std_rho.size() == scan.size();
  out.covariance_source = full ? SegmentCovarianceSource::kPosterior
                               : (diagonal ? SegmentCovarianceSource::kPosteriorDiagonal
                                           : SegmentCovarianceSource::kSensor);
  // Beam -> its index among the in-model beams (the order of range_covariance).
  std::vector<std::size_t> inmodel_index(scan.size(), 0);
  for (std::size_t j = 0; j < map.inmodel_beams.size(); ++j)
    inmodel_index[map.inmodel_beams[j]] = j;

  for (const BeamRange& region : map.regions) {
    std::vector<std::size_t> beams;
    // A region across the seam of a closed (full-turn) map scan runs on from the scan's end at
    // its start: in that order, as the wall is.
    const bool across_seam = region.first > region.last;
    for (std::size_t i = region.first; i < (across_seam ? scan.size() : region.last + 1); ++i)
      if (map.inmodel[i] != 0) beams.push_back(i);
    for (std::size_t i = 0; across_seam && i <= region.last; ++i)
      if (map.inmodel[i] != 0) beams.push_back(i);
    if (beams.size() < std::max<std::size_t>(options.min_points, 2)) continue;
    std::vector<double> ranges, bearings;
    for (const std::size_t i : beams) {
      ranges.push_back(map.rho[i]);
      bearings.push_back(scan.angles[i]);
    }
    const LineFit fit = FitLine(ranges, bearings);
    if (fit.rms > options.max_rms) continue;

    // d(radius, angle) / d(rho_i) by central differences of the fit.
    const std::size_t n = beams.size();
    Eigen::Matrix<double, 2, Eigen::Dynamic> jacobian(2, static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k) {
      const double h = 1e-6 * std::max(1.0, ranges[k]);
      std::vector<double> plus = ranges, minus = ranges;
      plus[k] += h;
      minus[k] -= h;
      const LineFit a = FitLine(plus, bearings), b = FitLine(minus, bearings);
      jacobian(0, static_cast<Eigen::Index>(k)) = (a.radius - b.radius) / (2.0 * h);
      jacobian(1, static_cast<Eigen::Index>(k)) = WrapAngle(a.angle - b.angle) / (2.0 * h);
    }
    Eigen::MatrixXd ranges_covariance =
        Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      if (full) {
        for (std::size_t l = 0; l < n; ++l)
          ranges_covariance(kk, static_cast<Eigen::Index>(l)) =
              posterior->range_covariance(static_cast<Eigen::Index>(inmodel_index[beams[k]]),
                                          static_cast<Eigen::Index>(inmodel_index[beams[l]]));
      } else {
        const double s = diagonal ? posterior->posterior_std_rho[beams[k]] : scan.sigma[beams[k]];
        ranges_covariance(kk, kk) = s * s;
      }
    }
    LineSegment segment;
    segment.radius = fit.radius;
    segment.angle = fit.angle;
    segment.covariance = jacobian * ranges_covariance * jacobian.transpose();
    const auto point = [&](std::size_t k) {
      return Vec2(ranges[k] * std::cos(bearings[k]), ranges[k] * std::sin(bearings[k]));
    };
    segment.start = Project(fit, point(0));
    segment.end = Project(fit, point(n - 1));
    segment.beams = region;
    segment.points = n;
    segment.rms = fit.rms;
    out.segments.push_back(segment);
  }
  return out;
}

std::string LineSegmentsToJson(const LineSegments& lines, const std::string& frame_id,
                               double stamp) {
  nlohmann::json j;
  j["format"] = "priormap.line_segments";
  j["version"] = 1;
  j["header"] = {{"frame_id", frame_id}, {"stamp", stamp}};
  const char* source = lines.covariance_source == SegmentCovarianceSource::kPosterior
                           ? "posterior"
                           : (lines.covariance_source == SegmentCovarianceSource::kPosteriorDiagonal
                                  ? "posterior_diagonal"
                                  : "sensor");
  j["covariance_source"] = source;
  j["line_segments"] = nlohmann::json::array();
  for (const LineSegment& s : lines.segments) {
    j["line_segments"].push_back(
        {{"radius", s.radius},
         {"angle", s.angle},
         {"covariance",
          {s.covariance(0, 0), s.covariance(0, 1), s.covariance(1, 0), s.covariance(1, 1)}},
         {"start", {s.start.x(), s.start.y()}},
         {"end", {s.end.x(), s.end.y()}},
         {"beams", {s.beams.first, s.beams.last}},
         {"points", s.points},
         {"rms", s.rms}});
  }
  return j.dump(2);
}

}  // namespace priormap::priorlets
