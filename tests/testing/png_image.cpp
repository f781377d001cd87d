#include "testing/png_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <stdexcept>

#include <cairo.h>

namespace priormap::testing {

Rgba ToRgba(const render::Color& c) {
  const auto byte = [](double v) { return static_cast<int>(std::lround(v * 255.0)); };
  return {byte(c.r), byte(c.g), byte(c.b), byte(c.a)};
}

bool Near(const Rgba& x, const Rgba& y, int tolerance) {
  return std::abs(x.r - y.r) <= tolerance && std::abs(x.g - y.g) <= tolerance &&
         std::abs(x.b - y.b) <= tolerance && std::abs(x.a - y.a) <= tolerance;
}

std::string Describe(const Rgba& c) {
  return "rgba(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) +
         ", " + std::to_string(c.a) + ")";
}

::testing::AssertionResult ColorNear(const Rgba& actual, const Rgba& expected, int tolerance) {
  if (Near(actual, expected, tolerance)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "got " << Describe(actual) << ", expected " << Describe(expected);
}

PixelPredicate Like(const Rgba& color) {
  return [color](const Rgba& p) {
    const auto close = [](int v, int c) { return std::abs(v - c) <= (3 * (255 - c)) / 10 + 2; };
    return close(p.r, color.r) && close(p.g, color.g) && close(p.b, color.b);
  };
}

PixelPredicate Like(const render::Color& color) {
  return Like(ToRgba(color));
}

PngImage::PngImage(const std::filesystem::path& path) {
  const std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface(
      cairo_image_surface_create_from_png(path.string().c_str()), cairo_surface_destroy);
  ok_ = cairo_surface_status(surface.get()) == CAIRO_STATUS_SUCCESS;
  if (!ok_) return;
  cairo_surface_flush(surface.get());
  width_ = cairo_image_surface_get_width(surface.get());
  height_ = cairo_image_surface_get_height(surface.get());
  const unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  const bool has_alpha = cairo_image_surface_get_format(surface.get()) == CAIRO_FORMAT_ARGB32;
  pixels_.reserve(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  for (int y = 0; y < height_; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + y * stride);
    for (int x = 0; x < width_; ++x) {
      const std::uint32_t p = row[x];
      const int a = has_alpha ? static_cast<int>(p >> 24) : 255;
      const auto channel = [&](int shift) {
        const int v = static_cast<int>((p >> shift) & 0xff);
        return a == 0 ? 0 : (v * 255 + a / 2) / a;  // undo premultiplication
      };
      pixels_.push_back({channel(16), channel(8), channel(0), a});
    }
  }
}

Rgba PngImage::At(int x, int y) const {
  if (x < 0 || x >= width_ || y < 0 || y >= height_) {
    throw std::out_of_range("pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") outside the " + std::to_string(width_) + "x" +
                            std::to_string(height_) + " image");
  }
  return pixels_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                 static_cast<std::size_t>(x)];
}

Rgba PngImage::At(const Vec2& device) const {
  return At(static_cast<int>(std::floor(device.x())), static_cast<int>(std::floor(device.y())));
}

int PngImage::Count(const PixelPredicate& predicate) const {
  int n = 0;
  for (const Rgba& pixel : pixels_) n += predicate(pixel) ? 1 : 0;
  return n;
}

int PngImage::Count(const Rgba& color, int tolerance) const {
  return Count([&](const Rgba& c) { return Near(c, color, tolerance); });
}

std::set<int> PngImage::ColumnsWith(const PixelPredicate& predicate) const {
  std::set<int> columns;
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      if (predicate(At(x, y))) columns.insert(x);
    }
  }
  return columns;
}

std::vector<std::pair<int, int>> PngImage::InkRuns(int row_from, int row_to, int gap) const {
  std::vector<std::pair<int, int>> runs;
  int blank = gap;
  for (int x = 0; x < width_; ++x) {
    bool ink = false;
    for (int y = std::max(row_from, 0); y < std::min(row_to, height_) && !ink; ++y) {
      const Rgba p = At(x, y);
      ink = p.r < 128 && p.g < 128 && p.b < 128;
    }
    if (!ink) {
      ++blank;
      continue;
    }
    if (blank >= gap) {
      runs.emplace_back(x, x);
    } else {
      runs.back().second = x;
    }
    blank = 0;
  }
  return runs;
}

}  // namespace priormap::testing
