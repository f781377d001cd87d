#include "raster_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>
#include <utility>
#include <vector>

#include <priormap/core/types.hpp>

namespace priormap::render::detail {
namespace {

// The mean of the finite values in the block of `factor` x `factor` cells at (row, col); NaN
// when there is none.
double BlockMean(const Eigen::MatrixXd& values, Eigen::Index row, Eigen::Index col,
                 Eigen::Index factor) {
  if (factor == 1) return values(row, col);
  double sum = 0.0;
  int count = 0;
  const Eigen::Index row_end = std::min(values.rows(), row + factor);
  const Eigen::Index col_end = std::min(values.cols(), col + factor);
  for (Eigen::Index r = row; r < row_end; ++r) {
    for (Eigen::Index c = col; c < col_end; ++c) {
      if (std::isfinite(values(r, c))) {
        sum += values(r, c);
        ++count;
      }
    }
  }
  return count > 0 ? sum / count : std::nan("");
}

// ARGB32 is premultiplied alpha in native byte order.
std::uint32_t Pixel(const Color& color) {
  const auto channel = [&](double v) {
    return static_cast<std::uint32_t>(std::lround(v * color.a * 255.0));
  };
  return (static_cast<std::uint32_t>(std::lround(color.a * 255.0)) << 24) |
         (channel(color.r) << 16) | (channel(color.g) << 8) | channel(color.b);
}

// Pixman samples a scaled image through the inverse of the scale in 16.16 fixed point, whose
// error grows with the image's pixels and the span they are seen over: cells of a row of three
// 8000 px wide landed 12 px off, and cells of 2e5 px were all drawn in the colour of one. Beyond
// about a million pixels, Cairo's 24.8 fixed-point coordinates wrap as well: a heat map 1e12
// times the world drew nothing. Within these bounds a boundary is off by at most about half a
// pixel; beyond them the raster is resampled here.
constexpr double kMaxSampledSpan = 65536.0;  // a pixel's size times the span, in device px^2
constexpr double kFarOutsidePx = 1e6;

// The part of `raster` (device pixels) inside the current clip; empty when none.
Box2 VisiblePart(cairo_t* cr, const Box2& raster) {
  double x1 = 0.0, y1 = 0.0, x2 = 0.0, y2 = 0.0;
  cairo_clip_extents(cr, &x1, &y1, &x2, &y2);
  return raster.intersection(Box2(Vec2(x1, y1), Vec2(x2, y2)));
}

// Whether Cairo draws the raster's image, of pixels `pixel` in size, where it belongs.
bool CairoSamplesInPlace(const Box2& raster, const Vec2& pixel, const Box2& visible) {
  const double span = visible.isEmpty() ? 0.0 : visible.sizes().maxCoeff();
  return raster.min().cwiseAbs().maxCoeff() < kFarOutsidePx &&
         raster.max().cwiseAbs().maxCoeff() < kFarOutsidePx &&
         pixel.maxCoeff() * span <= kMaxSampledSpan;
}

// Which of `count` image pixels of `size`, the first starting at `start`, holds the device
// pixel `index`'s centre: the nearest one for a centre beyond the image (clipped away) or a
// device coordinate lost to rounding.
int SourcePixel(int index, double start, double size, int count) {
  const double at = std::floor((index + 0.5 - start) / size);
  return !(at > 0.0) ? 0 : static_cast<int>(std::min(at, count - 1.0));
}

// The visible part of `image` (its top-left corner at `origin`, each pixel of size `pixel`),
// sampled at the centre of each device pixel of `visible` (as Cairo's nearest filter would) into
// an image drawn unscaled: neither far coordinates nor large pixels reach Cairo.
void PaintResampled(cairo_t* cr, const RasterImage& image, const Vec2& origin, const Vec2& pixel,
                    const Box2& visible) {
  // A raster whose place is not a number (a NaN corner) has no visible part to resample.
  if (visible.isEmpty() || !visible.min().allFinite() || !visible.max().allFinite()) return;
  const int x0 = static_cast<int>(std::floor(visible.min().x()));
  const int y0 = static_cast<int>(std::floor(visible.min().y()));
  const int width = static_cast<int>(std::ceil(visible.max().x())) - x0;
  const int height = static_cast<int>(std::ceil(visible.max().y())) - y0;
  cairo_surface_t* source = image.surface.get();
  const int source_width = cairo_image_surface_get_width(source);
  const int source_height = cairo_image_surface_get_height(source);
  std::vector<int> columns(static_cast<std::size_t>(width));
  for (int i = 0; i < width; ++i)
    columns[static_cast<std::size_t>(i)] = SourcePixel(x0 + i, origin.x(), pixel.x(), source_width);
  ImageSurface resampled(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height));
  if (cairo_surface_status(resampled.get()) != CAIRO_STATUS_SUCCESS) throw std::bad_alloc();
  const unsigned char* from = cairo_image_surface_get_data(source);
  const int from_stride = cairo_image_surface_get_stride(source);
  unsigned char* to = cairo_image_surface_get_data(resampled.get());
  const int to_stride = cairo_image_surface_get_stride(resampled.get());
  for (int j = 0; j < height; ++j) {
    const int source_row = SourcePixel(y0 + j, origin.y(), pixel.y(), source_height);
    const auto* in = reinterpret_cast<const std::uint32_t*>(
        from + static_cast<std::ptrdiff_t>(source_row) * from_stride);
    auto* out = reinterpret_cast<std::uint32_t*>(to + static_cast<std::ptrdiff_t>(j) * to_stride);
    for (int i = 0; i < width; ++i) out[i] = in[columns[static_cast<std::size_t>(i)]];
  }
  cairo_surface_mark_dirty(resampled.get());
  cairo_save(cr);
  cairo_rectangle(cr, visible.min().x(), visible.min().y(), visible.sizes().x(),
                  visible.sizes().y());
  cairo_clip(cr);
  cairo_set_source_surface(cr, resampled.get(), x0, y0);
  cairo_paint(cr);
  cairo_restore(cr);
}

}  // namespace

RasterImage ColormapImage(const Eigen::MatrixXd& values, Colormap colormap, double vmin,
                          double vmax, bool first_row_on_top) {
  const Eigen::Index longest = std::max(values.rows(), values.cols());
  const Eigen::Index factor = (longest + kMaxImageSide - 1) / kMaxImageSide;
  const auto rows = static_cast<int>((values.rows() + factor - 1) / factor);
  const auto cols = static_cast<int>((values.cols() + factor - 1) / factor);
  ImageSurface image(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, cols, rows));
  if (cairo_surface_status(image.get()) != CAIRO_STATUS_SUCCESS) throw std::bad_alloc();
  const int stride = cairo_image_surface_get_stride(image.get());
  unsigned char* data = cairo_image_surface_get_data(image.get());
  for (int r = 0; r < rows; ++r) {
    const int device_row = first_row_on_top ? r : rows - 1 - r;
    auto* row =
        reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(device_row) * stride);
    for (int c = 0; c < cols; ++c) {
      const double value = BlockMean(values, r * factor, c * factor, factor);
      row[c] = Pixel(MapColor(colormap, (value - vmin) / (vmax - vmin)));
    }
  }
  cairo_surface_mark_dirty(image.get());
  return {.surface = std::move(image),
          .factor = factor,
          .rows = values.rows(),
          .cols = values.cols(),
          .first_row_on_top = first_row_on_top};
}

void PaintRaster(cairo_t* cr, const RasterImage& image, double x, double y, double width,
                 double height) {
  const double cell_width = width / static_cast<double>(image.cols);
  const double cell_height = height / static_cast<double>(image.rows);
  // Rows of cells the image's top pixels hold beyond the values: the last, partial block's, which
  // is at the top when row 0 is at the bottom.
  const auto image_rows =
      static_cast<Eigen::Index>(cairo_image_surface_get_height(image.surface.get()));
  const auto overhang = static_cast<double>(image_rows * image.factor - image.rows);
  const double top = image.first_row_on_top ? y : y - overhang * cell_height;
  const Vec2 pixel(cell_width * static_cast<double>(image.factor),
                   cell_height * static_cast<double>(image.factor));
  const Box2 raster(Vec2(x, y), Vec2(x + width, y + height));
  if (!CairoSamplesInPlace(raster, pixel, VisiblePart(cr, raster))) {
    PaintResampled(cr, image, Vec2(x, top), pixel, VisiblePart(cr, raster));
    return;
  }
  cairo_save(cr);
  cairo_rectangle(cr, x, y, width, height);
  cairo_clip(cr);
  cairo_translate(cr, x, top);
  cairo_scale(cr, pixel.x(), pixel.y());
  cairo_set_source_surface(cr, image.surface.get(), 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
}

}  // namespace priormap::render::detail
