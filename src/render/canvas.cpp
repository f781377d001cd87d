#include "canvas.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/utf8.hpp>
#include <priormap/render/figure_size.hpp>

namespace priormap::render::detail {
namespace {

constexpr const char* kFont = "DejaVu Sans";

void CheckStatus(cairo_status_t status, const std::filesystem::path& path) {
  if (status != CAIRO_STATUS_SUCCESS) {
    throw IoError(
        fmt::format("{}: cannot write figure: {}", path.string(), cairo_status_to_string(status)));
  }
}

// One context a thread, kept for measuring text: layouts measure their labels before their
// canvas exists, and a surface and context made and destroyed for each label cost more than
// the measurement. A thread's own, so that figures may be drawn on several threads.
class TextMeasurer {
 public:
  TextMeasurer() = default;
  TextMeasurer(const TextMeasurer&) = delete;
  TextMeasurer& operator=(const TextMeasurer&) = delete;
  ~TextMeasurer() { Reset(); }

  // The context with the figures' font selected. A context in error (a NaN size puts it there,
  // and it then measures everything as 0) is replaced, as a fresh one per label never was.
  cairo_t* Get() {
    if (cr_ != nullptr && cairo_status(cr_) != CAIRO_STATUS_SUCCESS) Reset();
    if (cr_ == nullptr) {
      surface_ = cairo_recording_surface_create(CAIRO_CONTENT_ALPHA, nullptr);
      cr_ = cairo_create(surface_);
      cairo_select_font_face(cr_, kFont, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    }
    return cr_;
  }

 private:
  void Reset() {
    if (cr_ != nullptr) cairo_destroy(cr_);
    if (surface_ != nullptr) cairo_surface_destroy(surface_);
    cr_ = nullptr;
    surface_ = nullptr;
  }

  cairo_surface_t* surface_ = nullptr;
  cairo_t* cr_ = nullptr;
};

}  // namespace

void CheckFigureSize(double width, double height) {
  PRIORMAP_CHECK(std::isfinite(width) && std::isfinite(height) && width > 0.0 && height > 0.0,
                 fmt::format("a figure's width and height must be positive, finite numbers of "
                             "pixels (got {} x {} px)",
                             width, height));
  PRIORMAP_CHECK(
      FigureSizeFits(width, height),
      fmt::format("a figure of {:.0f} x {:.0f} px is too large to draw: figures are at "
                  "most {} px a side (the largest image Cairo makes) and {} px in all "
                  "(8192 x 8192)",
                  std::ceil(width), std::ceil(height), kMaxFigureSidePx, kMaxFigurePixels));
}

void CheckDashes(std::span<const double> dash_px) {
  // NaN and infinity Cairo takes, but draws as solid lines or single dashes.
  const bool lengths = std::all_of(dash_px.begin(), dash_px.end(),
                                   [](double v) { return std::isfinite(v) && v >= 0.0; });
  const bool not_all_zero = dash_px.empty() || std::any_of(dash_px.begin(), dash_px.end(),
                                                           [](double v) { return v > 0.0; });
  PRIORMAP_CHECK(lengths && not_all_zero,
                 fmt::format("a line's dash lengths must be finite and not negative, and not all 0 "
                             "(got [{}] px; empty for a solid line)",
                             fmt::join(dash_px, ", ")));
}

void CheckPixels(double px, std::string_view what) {
  PRIORMAP_CHECK(
      std::isfinite(px) && px >= 0.0,
      fmt::format("{} must be a finite number of pixels, at least 0 (got {})", what, px));
}

void CheckColor(const Color& color, std::string_view what) {
  PRIORMAP_CHECK(
      std::isfinite(color.r) && std::isfinite(color.g) && std::isfinite(color.b) &&
          std::isfinite(color.a),
      fmt::format("{} must have a finite r, g, b and a (got {}, {}, {}, {}; finite values "
                  "beyond [0, 1] count as the end they pass)",
                  what, color.r, color.g, color.b, color.a));
}

// Whole pixels: a PNG has them, and an SVG or PDF of the same figure should be the same size.
Canvas::Canvas(double width, double height) {
  CheckFigureSize(width, height);
  width_ = std::ceil(width);
  height_ = std::ceil(height);
  const cairo_rectangle_t extents{0.0, 0.0, width_, height_};
  recording_.reset(cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, &extents));
  cr_.reset(cairo_create(recording_.get()));
  cairo_set_source_rgb(cr(), 1.0, 1.0, 1.0);
  cairo_paint(cr());
}

void Canvas::Save(const std::filesystem::path& path,
                  const std::function<void(cairo_t*)>& overlay) const {
  const std::string extension = path.extension().string();
  // A drawing call that failed (Cairo then ignores every later one) must not pass as a figure.
  if (cairo_status(cr_.get()) != CAIRO_STATUS_SUCCESS) {
    throw IoError(fmt::format("{}: cannot draw figure: {}", path.string(),
                              cairo_status_to_string(cairo_status(cr_.get()))));
  }
  cairo_surface_flush(recording_.get());
  WriteFileAtomically(path, [&](const std::filesystem::path& temporary) {
    const std::string file = temporary.string();
    std::unique_ptr<cairo_surface_t, SurfaceDeleter> target;
    if (extension == ".png") {
      target.reset(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(width_),
                                              static_cast<int>(height_)));
    } else if (extension == ".svg") {
      target.reset(cairo_svg_surface_create(file.c_str(), width_, height_));
    } else if (extension == ".pdf") {
      target.reset(cairo_pdf_surface_create(file.c_str(), width_, height_));
    } else {
      throw IoError(fmt::format("{}: unsupported figure format '{}' (use .png, .svg or .pdf)",
                                path.string(), extension));
    }
    CheckStatus(cairo_surface_status(target.get()), path);
    {
      std::unique_ptr<cairo_t, ContextDeleter> context(cairo_create(target.get()));
      cairo_set_source_surface(context.get(), recording_.get(), 0.0, 0.0);
      cairo_paint(context.get());
      if (overlay) overlay(context.get());
      CheckStatus(cairo_status(context.get()), path);
    }
    if (extension == ".png") {
      CheckStatus(cairo_surface_write_to_png(target.get(), file.c_str()), path);
    }
    cairo_surface_finish(target.get());
    CheckStatus(cairo_surface_status(target.get()), path);
  });
}

void SetColor(cairo_t* cr, const Color& color) {
  cairo_set_source_rgba(cr, color.r, color.g, color.b, color.a);
}

std::string ValidUtf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    if (const std::optional<Utf8Char> c = DecodeUtf8(text, i)) {
      out.append(text.substr(i, c->length));
      i += c->length;
    } else {
      out.append("\xEF\xBF\xBD");  // U+FFFD for the one byte
      ++i;
    }
  }
  return out;
}

void DrawText(cairo_t* cr, const std::string& raw_text, double x, double y, double size,
              double align_x, double align_y, bool bold) {
  const std::string text = ValidUtf8(raw_text);
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  // Align on the font's cap height rather than the string's own ink, so labels line up.
  const double cap_height = 0.72 * size;
  cairo_move_to(cr, x - align_x * extents.x_advance, y + (1.0 - align_y) * cap_height);
  cairo_show_text(cr, text.c_str());
}

double TextWidth(const std::string& raw_text, double size) {
  thread_local TextMeasurer measurer;
  cairo_t* cr = measurer.Get();
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, ValidUtf8(raw_text).c_str(), &extents);
  return extents.x_advance;
}

}  // namespace priormap::render::detail

namespace priormap::render {

bool FigureSizeFits(double width_px, double height_px) {
  const double width = std::ceil(width_px), height = std::ceil(height_px);
  return width >= 1.0 && height >= 1.0 && width <= kMaxFigureSidePx && height <= kMaxFigureSidePx &&
         width * height <= static_cast<double>(kMaxFigurePixels);
}

double TextWidth(const std::string& text, double size_px) {
  return detail::TextWidth(text, size_px);
}

}  // namespace priormap::render

namespace priormap::render::detail {

namespace {
constexpr double kLegendFont = 11.0, kLegendRow = 18.0;
}  // namespace

double LegendHeight(std::size_t entries) {
  return kLegendRow * static_cast<double>(entries) + 8;
}

void DrawLegend(cairo_t* cr, const std::vector<std::pair<std::string, Color>>& entries, double x,
                double y, bool anchor_right) {
  if (entries.empty()) return;
  cairo_save(cr);
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, kLegendFont);
  double text_width = 0.0;
  for (const auto& entry : entries) {
    cairo_text_extents_t extents;
    cairo_text_extents(cr, ValidUtf8(entry.first).c_str(), &extents);
    text_width = std::max(text_width, extents.x_advance);
  }
  const double width = text_width + 44, height = LegendHeight(entries.size());
  const double x0 = anchor_right ? x - width : x;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
  cairo_rectangle(cr, x0, y, width, height);
  cairo_fill_preserve(cr);
  SetColor(cr, palette::kGray);
  cairo_set_line_width(cr, 1.0);
  cairo_set_dash(cr, nullptr, 0, 0.0);
  cairo_stroke(cr);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double row_y = y + 4 + kLegendRow * (static_cast<double>(i) + 0.5);
    SetColor(cr, entries[i].second);
    cairo_set_line_width(cr, 4.0);
    cairo_move_to(cr, x0 + 8, row_y);
    cairo_line_to(cr, x0 + 30, row_y);
    cairo_stroke(cr);
    SetColor(cr, palette::kBlack);
    DrawText(cr, entries[i].first, x0 + 36, row_y, kLegendFont, 0.0, 0.5);
  }
  cairo_restore(cr);
}

void DrawLegendRow(cairo_t* cr, const std::vector<std::pair<std::string, Color>>& entries,
                   double center_x, double y) {
  constexpr double kSwatch = 22.0, kGap = 6.0, kSpacing = 18.0;
  cairo_save(cr);
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, kLegendFont);
  std::vector<double> widths;
  double total = 0.0;
  for (const auto& entry : entries) {
    cairo_text_extents_t extents;
    cairo_text_extents(cr, ValidUtf8(entry.first).c_str(), &extents);
    widths.push_back(kSwatch + kGap + extents.x_advance);
    total += widths.back() + (widths.size() > 1 ? kSpacing : 0.0);
  }
  double x = center_x - total / 2;
  cairo_set_dash(cr, nullptr, 0, 0.0);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    SetColor(cr, entries[i].second);
    cairo_set_line_width(cr, 4.0);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + kSwatch, y);
    cairo_stroke(cr);
    SetColor(cr, palette::kBlack);
    DrawText(cr, entries[i].first, x + kSwatch + kGap, y, kLegendFont, 0.0, 0.5);
    x += widths[i] + kSpacing;
  }
  cairo_restore(cr);
}

}  // namespace priormap::render::detail
