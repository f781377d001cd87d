#pragma once
/// x/y line plots with axes, ticks, labels and a legend (error over time, per-beam residuals).

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <priormap/render/color.hpp>
#include <priormap/render/figure_size.hpp>

namespace priormap::render {

struct Series {
  std::vector<double> x{};
  std::vector<double> y{};       ///< same size as x; NaN breaks the line
  std::string label{};           ///< empty: not in the legend
  std::optional<Color> color{};  ///< default: the palette colour of the series' index
  double width_px = 1.5;         ///< finite, not negative (LinePlot::Add checks)
  bool markers = false;          ///< draw a dot at each point, no line
  /// Lengths along the line, on and off by turns, repeated; empty: solid. Finite, not negative
  /// and not all 0 (LinePlot::Add checks).
  std::vector<double> dash_px{};
};

struct LinePlotOptions {
  /// At least 200 (smaller grows to it, and when tick labels leave no plot); negative sizes are a
  /// ContractError.
  int width_px = 800;
  int height_px = 450;  ///< at least 150 (as width_px)
  std::string title{};
  std::string x_label{};
  std::string y_label{};
  /// Default: the data's. Given: finite, lo < hi; data beyond it is clipped.
  std::optional<std::pair<double, double>> x_range{};
  std::optional<std::pair<double, double>> y_range{};
};

class LinePlot {
 public:
  /// Throws ContractError when the plot's size is negative or does not fit (figure_size.hpp).
  explicit LinePlot(LinePlotOptions options = {});

  /// Throws ContractError for a width or dash pattern as Series says it may not be.
  void Add(Series series);
  /// A horizontal reference line (e.g. zero error, a 3-sigma bound).
  void AddHorizontalLine(double y, const Color& color, std::string label = "");

  /// Writes PNG, SVG or PDF according to the extension, atomically. Throws IoError, and
  /// ContractError when a series has x and y of different sizes or a range is not as above.
  void Save(const std::filesystem::path& path) const;

 private:
  LinePlotOptions options_;
  std::vector<Series> series_;
  std::vector<Series> horizontal_lines_;  ///< y = {value, value}; x spans the axis when drawn
};

}  // namespace priormap::render
