// Read a CARMEN log (plain or .gz), report what is in it, and save it as priormap JSON.
//   example_02_read_carmen_log ../shared/data/laser-corrected/intel-corrected.log.gz intel.json
#include <cstdio>
#include <exception>
#include <string>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/json_io.hpp>

// Bad input comes back as a Result; what cannot be done (writing OUT.json into a directory
// that does not exist) throws: say what, and exit 1.
int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s LOG [OUT.json]\n", argv[0]);
    return 2;
  }
  priormap::CarmenReadStats stats;
  const priormap::Result<priormap::Log> log = priormap::ReadCarmenLog(argv[1], {}, &stats);
  if (!log) {
    // Every problem comes with file:line:col and what was expected.
    std::fprintf(stderr, "%s\n", log.error().c_str());
    return 1;
  }
  std::size_t valid = 0, beams = 0;
  for (const priormap::Scan& scan : log.value().scans) {
    valid += scan.NumValid();
    beams += scan.size();
  }
  // Readings at or beyond the detected threshold (a little below the sensor's "no return"
  // value, e.g. 81.33 m for 81.83 m) are max-range readings, not walls.
  std::printf("%zu scans, %zu readings of which %zu valid; max-range threshold %s\n",
              log.value().scans.size(), beams, valid,
              stats.detected_max_range
                  ? (std::to_string(*stats.detected_max_range) + " m (detected)").c_str()
                  : "none detected");
  if (argc > 2) {
    priormap::WriteJsonLog(log.value(), argv[2]);
    std::printf("wrote %s\n", argv[2]);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
