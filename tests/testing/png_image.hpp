#pragma once
// PNG files read back with Cairo, for tests that look at the pixels of rendered figures and plots.

#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/types.hpp>
#include <priormap/render/color.hpp>

namespace priormap::testing {

/// 8-bit colour, not premultiplied.
struct Rgba {
  int r = 0, g = 0, b = 0, a = 0;
};

/// `c` in 8 bits a channel (rounded).
Rgba ToRgba(const render::Color& c);

/// Every channel (alpha too) within `tolerance`.
bool Near(const Rgba& x, const Rgba& y, int tolerance = 1);

/// "rgba(r, g, b, a)".
std::string Describe(const Rgba& c);

/// Near(actual, expected, tolerance), with both colours in the failure message.
::testing::AssertionResult ColorNear(const Rgba& actual, const Rgba& expected, int tolerance = 1);

using PixelPredicate = std::function<bool(const Rgba&)>;

/// Pixels that are `color` drawn over white with at least 70% coverage (anti-aliased thin lines
/// rarely cover a whole pixel); alpha is not looked at.
PixelPredicate Like(const Rgba& color);
PixelPredicate Like(const render::Color& color);

/// A PNG file read back with Cairo (decoded once, when constructed).
class PngImage {
 public:
  explicit PngImage(const std::filesystem::path& path);

  /// False when the file could not be read as a PNG.
  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

  /// Pixel (x, y), not premultiplied; alpha is 255 for images without an alpha channel. Throws
  /// std::out_of_range outside the image.
  [[nodiscard]] Rgba At(int x, int y) const;
  /// The pixel containing a device point.
  [[nodiscard]] Rgba At(const Vec2& device) const;

  /// How many pixels satisfy `predicate`.
  [[nodiscard]] int Count(const PixelPredicate& predicate) const;
  /// How many pixels are Near `color`.
  [[nodiscard]] int Count(const Rgba& color, int tolerance = 1) const;

  /// The runs [first, last] of columns that hold ink (black text, anti-aliased: every channel
  /// below 128) in rows [row_from, row_to), split where at least `gap` columns hold none: along
  /// a row of tick labels, one run a label.
  [[nodiscard]] std::vector<std::pair<int, int>> InkRuns(int row_from, int row_to, int gap) const;

  /// Columns that hold at least one pixel satisfying `predicate`.
  [[nodiscard]] std::set<int> ColumnsWith(const PixelPredicate& predicate) const;

 private:
  bool ok_ = false;
  int width_ = 0;
  int height_ = 0;
  std::vector<Rgba> pixels_;  ///< row by row
};

}  // namespace priormap::testing
