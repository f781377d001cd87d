#pragma once
// A drawing recorded once (Cairo recording surface) and replayed into PNG, SVG or PDF files.

#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <cairo.h>

#include <priormap/render/color.hpp>

namespace priormap::render::detail {

class Canvas {
 public:
  /// A white canvas of width x height pixels (points in SVG/PDF), each rounded up to a whole
  /// pixel. Throws ContractError, before allocating anything, for a size FigureSizeFits refuses.
  Canvas(double width, double height);

  [[nodiscard]] cairo_t* cr() const { return cr_.get(); }
  [[nodiscard]] double width() const { return width_; }
  [[nodiscard]] double height() const { return height_; }

  /// Writes the drawing, then `overlay` on top of it (legends, frames); the format follows
  /// the extension. Throws IoError.
  void Save(const std::filesystem::path& path,
            const std::function<void(cairo_t*)>& overlay = nullptr) const;

 private:
  struct SurfaceDeleter {
    void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
  };
  struct ContextDeleter {
    void operator()(cairo_t* c) const { cairo_destroy(c); }
  };
  double width_ = 0.0;
  double height_ = 0.0;
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> recording_;
  std::unique_ptr<cairo_t, ContextDeleter> cr_;
};

/// Throws ContractError naming the size and the limits unless FigureSizeFits(width, height); a
/// size that is not a positive number of pixels (NaN, negative) is named as such, not as too large.
void CheckFigureSize(double width, double height);

/// Throws ContractError naming `what` (a caller's field, "a line's width_px") and the value unless
/// `px` is a finite number of pixels, at least 0. Cairo takes NaN and infinite widths and radii,
/// and draws nothing, or spends minutes drawing a disc of 1e300 pixels.
void CheckPixels(double px, std::string_view what);

/// Throws ContractError naming `what` ("a point's color") and the colour unless its r, g, b and a
/// are finite. Cairo clamps finite values to [0, 1], but turns NaN into whatever the conversion
/// to an integer gives (0: black, or nothing at all for NaN alpha).
void CheckColor(const Color& color, std::string_view what);

/// Throws ContractError naming the pattern unless Cairo can draw the dash pattern `dash_px`:
/// empty (solid), or lengths that are finite and not negative, not all 0. Cairo refuses the
/// others and then draws nothing more, which came to light only when the figure was saved.
void CheckDashes(std::span<const double> dash_px);

void SetColor(cairo_t* cr, const Color& color);
/// `text` with each byte that is not part of a valid UTF-8 sequence replaced by U+FFFD: Cairo
/// stops drawing altogether at invalid UTF-8, and titles hold file names of any bytes.
[[nodiscard]] std::string ValidUtf8(std::string_view text);
/// Text at (x, y): `align_x` 0 puts x at the left end, 0.5 at the centre, 1 at the right end;
/// `align_y` 0 puts y at the top of capital letters, 0.5 at their middle, 1 on the baseline.
void DrawText(cairo_t* cr, const std::string& text, double x, double y, double size, double align_x,
              double align_y, bool bold = false);

/// The advance width of `text` drawn by DrawText at `size` (not bold), without a canvas to draw
/// on: measured with one context kept for the calling thread.
[[nodiscard]] double TextWidth(const std::string& text, double size);

/// Height in pixels of a legend box with `entries` rows.
[[nodiscard]] double LegendHeight(std::size_t entries);

/// A legend box: one coloured swatch and label per entry. (x, y) is its top-left corner, or its
/// top-right corner with `anchor_right`.
void DrawLegend(cairo_t* cr, const std::vector<std::pair<std::string, Color>>& entries, double x,
                double y, bool anchor_right);

/// A legend as one row of swatches and labels, centred on `center_x`, with `y` the middle of the
/// row.
void DrawLegendRow(cairo_t* cr, const std::vector<std::pair<std::string, Color>>& entries,
                   double center_x, double y);

}  // namespace priormap::render::detail
