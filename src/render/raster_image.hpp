#pragma once
// A raster of values as a Cairo image in a colour map, at most kMaxImageSide pixels on a side:
// Cairo refuses wider images, and a figure a few thousand points wide shows no more.

#include <memory>

#include <Eigen/Core>
#include <cairo.h>

#include <priormap/render/color.hpp>

namespace priormap::render::detail {

inline constexpr int kMaxImageSide = 4096;

struct ImageDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
using ImageSurface = std::unique_ptr<cairo_surface_t, ImageDeleter>;

/// A raster's image: each pixel a block of factor x factor of its `rows` x `cols` values.
struct RasterImage {
  ImageSurface surface;
  Eigen::Index factor = 1;
  Eigen::Index rows = 0, cols = 0;
  bool first_row_on_top = false;
};

/// `values` (row 0 at the bottom, or at the top with `first_row_on_top`) mapped through
/// `colormap` over [vmin, vmax]; NaN is transparent. A raster wider or taller than kMaxImageSide
/// is shrunk by a whole factor, each pixel the mean of the finite values of its block. Throws
/// std::bad_alloc when Cairo cannot make the image.
[[nodiscard]] RasterImage ColormapImage(const Eigen::MatrixXd& values, Colormap colormap,
                                        double vmin, double vmax, bool first_row_on_top);

/// Paints `image` so that its values' cells fill the device rectangle (x, y, width, height)
/// exactly: the partial blocks of the last row and column of a shrunk image reach past it and are
/// clipped. A rectangle reaching far beyond the clip, or of image pixels too large for Cairo to
/// place exactly, is painted only where it is visible, resampled to device pixels. Precondition:
/// the current transformation is the identity. Throws std::bad_alloc as ColormapImage.
void PaintRaster(cairo_t* cr, const RasterImage& image, double x, double y, double width,
                 double height);

}  // namespace priormap::render::detail
