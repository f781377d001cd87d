#pragma once
/// The figure of one MAP scan and its posterior, after Figs. 3-6 of de la Puente & Censi: five
/// panels of one drawing, saved as PNG, SVG or PDF.
///  (a) the measured scan, the corrected points and the topology (dashed: region borders, solid:
///      surface borders), outliers as crosses, the sensor at the origin (sensor frame);
///  (b) the normal angle per beam: initial, corrected, ground truth (when the scan has it) and the
///      bounds of the final solve;
///  (c) the largest intrinsic scan eigenvariations as varied scans rho +- k sigma v (exaggerated
///      by k, stated in the title);
///  (d) prior and posterior standard deviation of each range (log scale);
///  (e) the posterior covariance of the in-model ranges as a heat map;
///  and a short summary (counts, degrees of freedom). Without a posterior (Posterior::computed
///  false) panels (c)-(e) show why instead.

#include <filesystem>
#include <memory>
#include <string>

#include <priormap/core/scan.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/posterior.hpp>
#include <priormap/render/figure_size.hpp>

namespace priormap::render {

struct MapScanFigureOptions {
  int width_px = 1400;  ///< the height follows (about 1.2 times the width); not negative
  std::string title{};  ///< over the whole figure (empty: none)
  /// Panel (c): how many intrinsic eigenvariations, at most (the largest).
  int eigenvariations = 3;
  /// Panel (c): each eigenvariation is exaggerated (by 1, 2 or 5 times a power of ten) so that
  /// its largest range change is about this fraction of the scan's extent.
  double eigenvariation_extent_fraction = 0.04;
  /// Panel (e): larger covariances are averaged over square blocks to at most this many rows.
  int max_heat_map_cells = 300;
};

class MapScanFigure {
 public:
  /// Draws the figure of `map` = EstimateMapScan(scan, ...) and `posterior` = AnalysePosterior(
  /// scan, ..., map, ...). Preconditions: the per-beam vectors of `map` (and of `posterior` when
  /// computed) have scan.size() entries; range_covariance, when not empty, is m x m with
  /// m = map.inmodel_beams.size(); the figure's size fits (figure_size.hpp: width_px up to
  /// 7,461 with a title, 7,478 without), which is checked before anything is drawn.
  MapScanFigure(const Scan& scan, const priorlets::MapScan& map,
                const priorlets::Posterior& posterior, const MapScanFigureOptions& options = {});
  ~MapScanFigure();
  MapScanFigure(MapScanFigure&&) noexcept;
  MapScanFigure& operator=(MapScanFigure&&) noexcept;

  /// Writes PNG, SVG or PDF according to the extension, atomically. Throws IoError.
  void Save(const std::filesystem::path& path) const;

  [[nodiscard]] int width_px() const;
  [[nodiscard]] int height_px() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace priormap::render
