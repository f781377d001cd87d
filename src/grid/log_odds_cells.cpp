#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/log_odds_cells.hpp>

namespace priormap::grid {
namespace detail {

// A line of cells walked along its major axis a (one step of sa per cell) while its minor axis b
// advances by sb after m_k of the first k steps. With Bresenham's error term starting at
// h = major / 2 and losing `minor` per step, m_k = ceil((k minor - h) / major)
// = floor((k minor + c) / major) with c = major - 1 - h.
struct Line {
  bool x_major = true;
  std::int64_t a0 = 0, b0 = 0;
  int sa = 1, sb = 1;
  std::uint64_t major = 0, minor = 0, c = 0;
};

}  // namespace detail

namespace {

using detail::Line;

Line LineBetween(int x0, int y0, int x1, int y1) {
  const std::int64_t dx = std::int64_t{x1} - x0;
  const std::int64_t dy = std::int64_t{y1} - y0;
  Line line;
  line.x_major = std::abs(dx) >= std::abs(dy);
  line.a0 = line.x_major ? x0 : y0;
  line.b0 = line.x_major ? y0 : x0;
  const std::int64_t da = line.x_major ? dx : dy;
  const std::int64_t db = line.x_major ? dy : dx;
  line.sa = da >= 0 ? 1 : -1;
  line.sb = db > 0 ? 1 : -1;
  line.major = static_cast<std::uint64_t>(std::abs(da));
  line.minor = static_cast<std::uint64_t>(std::abs(db));
  line.c = line.major == 0 ? 0 : line.major - 1 - line.major / 2;
  return line;
}

// Up to this many steps a 32.32 fixed-point accumulator gives m_k exactly: with its start and its
// step rounded up, accumulator_k = ceil(2^32 c / major) + k ceil(2^32 minor / major) exceeds
// 2^32 (k minor + c) / major by less than k + 1 <= major, and a value of (k minor + c) / major
// that is not an integer is at least 1 / major below the next one: 2^32 / major >= major units
// of the accumulator while major <= 2^16, so the accumulator's integer part is the floor.
constexpr std::uint64_t kExactSteps = 65535;

std::uint64_t CeilDiv(std::uint64_t n, std::uint64_t d) {
  return n / d + (n % d != 0 ? 1 : 0);
}

// The cells of a line with offsets major_offset[sa k] + minor_offset[kMinorSign m_k] where
// m_k = accumulator_k >> 32; the sign is a template parameter so that the loop has no multiply.
// Every loop-invariant value is a local, as the byte-sized cells could alias any memory.
template <int kMinorSign>
void TraceExactLoop(const std::uint32_t* major_offset, const std::uint32_t* major_end,
                    std::ptrdiff_t sa, const std::uint32_t* minor_offset, std::uint64_t accumulator,
                    std::uint64_t step, std::int8_t* cells, const CellUpdate& along) {
  for (; major_offset != major_end; major_offset += sa) {
    const auto m = static_cast<std::ptrdiff_t>(accumulator >> 32);
    accumulator += step;
    std::int8_t& cell = cells[*major_offset + minor_offset[kMinorSign * m]];
    cell = along(cell);
  }
}

}  // namespace

CellUpdate::CellUpdate(int delta, int limit) {
  if (!(limit > 0 && limit <= INT8_MAX && std::abs(delta) <= limit))
    throw std::invalid_argument(fmt::format("bad cell update {} within ±{}", delta, limit));
  for (int state = INT8_MIN; state <= INT8_MAX; ++state) {
    const int current = state == kUnobserved ? 0 : state;
    next_[static_cast<std::uint8_t>(state)] =
        static_cast<std::int8_t>(std::clamp(current + delta, -limit, limit));
  }
}

LogOddsCells::LogOddsCells(int width, int height) : width_(width), height_(height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument(fmt::format("a raster of {}x{} cells", width, height));
  // Whole tiles: the last column and row of tiles are padded.
  const std::uint64_t tiles_x = (static_cast<std::uint64_t>(width) + kTile - 1) / kTile;
  const std::uint64_t tiles_y = (static_cast<std::uint64_t>(height) + kTile - 1) / kTile;
  const std::uint64_t tile_row = tiles_x * kTile * kTile;
  if (tile_row * tiles_y > UINT32_MAX)
    throw std::invalid_argument(fmt::format("{}x{} cells exceed 4e9", width, height));
  // In 64 bits: past 2^25 columns, ix / 8 * 64 overflows an int (undefined behaviour).
  column_offset_.resize(static_cast<std::size_t>(width));
  for (int ix = 0; ix < width; ++ix)
    column_offset_[static_cast<std::size_t>(ix)] =
        static_cast<std::uint32_t>(static_cast<std::uint64_t>(ix / kTile) * kTile * kTile +
                                   static_cast<std::uint64_t>(ix % kTile));
  row_offset_.resize(static_cast<std::size_t>(height));
  for (int iy = 0; iy < height; ++iy)
    row_offset_[static_cast<std::size_t>(iy)] =
        static_cast<std::uint32_t>(static_cast<std::uint64_t>(iy / kTile) * tile_row +
                                   static_cast<std::uint64_t>(iy % kTile * kTile));
  cells_.assign(static_cast<std::size_t>(tile_row * tiles_y), kUnobserved);
}

void LogOddsCells::TraceLine(int x0, int y0, int x1, int y1, const CellUpdate& along,
                             const CellUpdate& last) {
  // The raster is a rectangle: with both ends inside, so is every cell between.
  const bool inside = Contains(x0, y0) && Contains(x1, y1);
  const Line line = LineBetween(x0, y0, x1, y1);
  if (line.major == 0) {
    // A single cell: nothing before the end.
  } else if (inside && line.major <= kExactSteps) {
    TraceExact(line, along);
  } else if (inside) {
    TraceStepwise<false>(line, along);
  } else {
    TraceStepwise<true>(line, along);
  }
  if (Contains(x1, y1)) Apply(x1, y1, last);
}

void LogOddsCells::TraceExact(const Line& line, const CellUpdate& along) {
  // The minor coordinate is read off an accumulator: the loop carries two additions, not
  // Bresenham's error term and its test, whose latency bounded it.
  const std::uint64_t step = CeilDiv(line.minor << 32, line.major);
  const std::uint64_t accumulator = CeilDiv(line.c << 32, line.major);
  const std::uint32_t* major_offset =
      (line.x_major ? column_offset_ : row_offset_).data() + line.a0;
  const std::uint32_t* minor_offset =
      (line.x_major ? row_offset_ : column_offset_).data() + line.b0;
  const std::uint32_t* major_end = major_offset + line.sa * static_cast<std::int64_t>(line.major);
  if (line.sb > 0) {
    TraceExactLoop<1>(major_offset, major_end, line.sa, minor_offset, accumulator, step,
                      cells_.data(), along);
  } else {
    TraceExactLoop<-1>(major_offset, major_end, line.sa, minor_offset, accumulator, step,
                       cells_.data(), along);
  }
}

template <bool kChecked>
void LogOddsCells::TraceStepwise(const Line& line, const CellUpdate& along) {
  const std::int64_t a_size = line.x_major ? width_ : height_;
  const std::int64_t b_size = line.x_major ? height_ : width_;
  // Only the steps whose major coordinate is inside can touch the raster.
  std::uint64_t k_begin = 0, k_end = line.major;
  if constexpr (kChecked) {
    const std::int64_t first = line.sa > 0 ? -line.a0 : line.a0 - (a_size - 1);
    const std::int64_t past = line.sa > 0 ? a_size - line.a0 : line.a0 + 1;
    k_begin = static_cast<std::uint64_t>(std::max<std::int64_t>(first, 0));
    k_end = static_cast<std::uint64_t>(
        std::clamp<std::int64_t>(past, 0, static_cast<std::int64_t>(line.major)));
    if (k_begin >= k_end) return;
  }
  // Bresenham's state after k_begin steps. k minor + c < 2^64 (both factors are below 2^32),
  // and the error term, in [0, major), is exact in modular arithmetic.
  const std::uint64_t m = (k_begin * line.minor + line.c) / line.major;
  auto error = static_cast<std::int64_t>(line.major / 2 + m * line.major - k_begin * line.minor);
  std::int64_t a = line.a0 + line.sa * static_cast<std::int64_t>(k_begin);
  std::int64_t b = line.b0 + line.sb * static_cast<std::int64_t>(m);
  const auto minor = static_cast<std::int64_t>(line.minor);
  const auto major = static_cast<std::int64_t>(line.major);
  const std::vector<std::uint32_t>& major_offset = line.x_major ? column_offset_ : row_offset_;
  const std::vector<std::uint32_t>& minor_offset = line.x_major ? row_offset_ : column_offset_;
  for (std::uint64_t k = k_begin; k < k_end; ++k) {
    if (!kChecked || (b >= 0 && b < b_size)) {
      std::int8_t& cell = cells_[major_offset[static_cast<std::size_t>(a)] +
                                 minor_offset[static_cast<std::size_t>(b)]];
      cell = along(cell);
    }
    error -= minor;
    if (error < 0) {
      error += major;
      b += line.sb;
    }
    a += line.sa;
  }
}

LogOddsCells CellsCovering(const Box2& extent, double resolution, double max_cells) {
  if (extent.isEmpty()) throw std::invalid_argument("the grid's extent is empty");
  // A NaN corner is not empty for Eigen and rounds to a single cell.
  if (!extent.min().allFinite() || !extent.max().allFinite())
    throw std::invalid_argument(fmt::format("the grid's extent [{}, {}] x [{}, {}] is not finite",
                                            extent.min().x(), extent.max().x(), extent.min().y(),
                                            extent.max().y()));
  if (!(resolution > 0.0 && std::isfinite(resolution)))
    throw std::invalid_argument(
        fmt::format("the grid's resolution {} m is not a positive size", resolution));
  const Vec2 size = extent.sizes() / resolution;
  const double width = std::max(1.0, std::ceil(size.x()));
  const double height = std::max(1.0, std::ceil(size.y()));
  const double limit = std::min(max_cells, 4e9);
  // Each side must also fit the cells' int coordinates: one row of 3e9 cells is under 4e9.
  const double longest_side = static_cast<double>(std::numeric_limits<int>::max());
  if (width > longest_side || height > longest_side)
    throw std::invalid_argument(fmt::format(
        "a grid of {:.1f} m x {:.1f} m at {} m would be {:.3g} x {:.3g} cells, a side longer "
        "than {} cells: use a coarser resolution or a shorter insertion range",
        extent.sizes().x(), extent.sizes().y(), resolution, width, height, longest_side));
  if (!(width * height <= limit)) {
    throw std::invalid_argument(fmt::format(
        "a grid of {:.1f} m x {:.1f} m at {} m would have {:.3g} cells, more than {:.3g} (about "
        "17 bytes a cell): use a coarser resolution, a shorter insertion range or fewer scans, or "
        "raise the limit (grid --max-cells)",
        extent.sizes().x(), extent.sizes().y(), resolution, width * height, limit));
  }
  return {static_cast<int>(width), static_cast<int>(height)};
}

double LogOddsOf(std::int8_t cell, double scale) {
  return cell == LogOddsCells::kUnobserved ? 0.0 : cell / scale;
}

OccupancyRaster RasterOf(const LogOddsCells& cells, const Vec2& origin, double resolution,
                         double scale) {
  OccupancyRaster raster;
  raster.origin = origin;
  raster.resolution = resolution;
  raster.probability.resize(cells.height(), cells.width());
  // One probability per fixed-point state.
  std::array<double, 256> probability{};
  for (int state = INT8_MIN; state <= INT8_MAX; ++state)
    probability[static_cast<std::uint8_t>(state)] = state == LogOddsCells::kUnobserved
                                                        ? std::numeric_limits<double>::quiet_NaN()
                                                        : 1.0 / (1.0 + std::exp(-state / scale));
  for (int iy = 0; iy < cells.height(); ++iy)
    for (int ix = 0; ix < cells.width(); ++ix)
      raster.probability(iy, ix) = probability[static_cast<std::uint8_t>(cells.Get(ix, iy))];
  return raster;
}

}  // namespace priormap::grid
