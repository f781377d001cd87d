#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/map_server.hpp>

namespace priormap {

unsigned char MapServerPixel(double probability) {
  if (std::isnan(probability)) return 205;
  const double p = std::clamp(probability, 0.0, 1.0);
  return static_cast<unsigned char>(std::lround((1.0 - p) * 255.0));
}

void WriteMapServerMap(const std::filesystem::path& yaml_path, const OccupancyRaster& raster) {
  const Eigen::MatrixXd& p = raster.probability;
  std::string pgm = fmt::format("P5\n{} {}\n255\n", p.cols(), p.rows());
  const std::size_t header = pgm.size();
  pgm.resize(header + static_cast<std::size_t>(p.rows() * p.cols()));
  std::size_t at = header;
  for (Eigen::Index row = p.rows() - 1; row >= 0; --row)  // top of the map first
    for (Eigen::Index col = 0; col < p.cols(); ++col)
      pgm[at++] = static_cast<char>(MapServerPixel(p(row, col)));
  std::filesystem::path pgm_path = yaml_path;
  pgm_path.replace_extension(".pgm");
  WriteTextFileAtomically(pgm_path, pgm);
  WriteTextFileAtomically(
      yaml_path, fmt::format("image: {}\nresolution: {}\norigin: [{}, {}, 0.0]\nnegate: 0\n"
                             "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n",
                             pgm_path.filename().string(), raster.resolution, raster.origin.x(),
                             raster.origin.y()));
}

}  // namespace priormap
