#include "raster_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>
#include <utility>

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
  cairo_save(cr);
  cairo_rectangle(cr, x, y, width, height);
  cairo_clip(cr);
  cairo_translate(cr, x, top);
  cairo_scale(cr, cell_width * static_cast<double>(image.factor),
              cell_height * static_cast<double>(image.factor));
  cairo_set_source_surface(cr, image.surface.get(), 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
}

}  // namespace priormap::render::detail
