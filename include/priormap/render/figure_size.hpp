#pragma once
/// The largest figure priormap draws. Every figure (Figure, LinePlot, MapScanFigure, StudyPlot)
/// checks its size when it is made, before it draws or allocates anything, and throws
/// ContractError naming the size and the limit beyond these:
///  - kMaxFigureSidePx a side: Cairo makes no image wider or taller, and a PNG is drawn into one.
///    Without the check, a figure too wide was drawn in full and then failed to save.
///  - kMaxFigurePixels in all: 8192 x 8192, the 256 MiB of the 32-bit image a PNG is drawn
///    into. It admits every figure the command line draws (`plot --width` up to 8,000 px, square)
///    and refuses what would take gigabytes (30,000 x 30,000 px: 3.6 GB), as image libraries do
///    (Pillow warns beyond 89 MP).
/// The limits hold for SVG and PDF too. The format is chosen only when saving, after the drawing,
/// and the same figure is often saved as both; a vector figure holds raster layers too
/// (Figure::Points' layer of many points is sized from the figure, up to 16 MP, beyond which
/// the points stay millions of vector discs; heat maps are images of up to 4096 px a side); and
/// Cairo's 24.8 fixed-point coordinates wrap at 8.4 million pixels anyway. A larger SVG or PDF
/// shows nothing more than a smaller one viewed zoomed in.

#include <cstdint>

namespace priormap::render {

inline constexpr int kMaxFigureSidePx = 32767;
inline constexpr std::int64_t kMaxFigurePixels = std::int64_t{8192} * 8192;

/// Whether a figure of width_px x height_px (each rounded up to a whole pixel) can be drawn and
/// saved: both finite and positive, neither beyond kMaxFigureSidePx, their product not beyond
/// kMaxFigurePixels. For callers sizing figures from user input or data, to refuse first.
[[nodiscard]] bool FigureSizeFits(double width_px, double height_px);

}  // namespace priormap::render
