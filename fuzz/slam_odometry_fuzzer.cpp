// libFuzzer harness for the odometry CSV reader of `priormap slam run`. Besides crashes and
// sanitizer reports it checks that a rejected file gets diagnostics located inside the text, that
// accepted steps are contiguous and in time order, and that they are written back so that reading
// them again gives the same steps bit for bit, and the same text.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/slam/slam_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;
using priormap::fuzz::SameBits;
using priormap::slam::BicycleControl;
using priormap::slam::MotionStep;
using priormap::slam::Odometry;

namespace {

// Increment standard deviations may be NaN ("use the default"), of any payload.
bool Same(double a, double b) {
  return SameBits(a, b) || (std::isnan(a) && std::isnan(b));
}

bool SameStep(const MotionStep& a, const MotionStep& b) {
  if (!Same(a.time, b.time) || !Same(a.dt, b.dt) || a.motion.index() != b.motion.index())
    return false;
  for (int i = 0; i < 3; ++i) {
    if (!Same(a.increment_std[i], b.increment_std[i])) return false;
  }
  if (const auto* ca = std::get_if<BicycleControl>(&a.motion)) {
    const auto& cb = std::get<BicycleControl>(b.motion);
    return Same(ca->speed, cb.speed) && Same(ca->steer, cb.steer);
  }
  const auto& ia = std::get<priormap::Se2>(a.motion);
  const auto& ib = std::get<priormap::Se2>(b.motion);
  return Same(ia.x(), ib.x()) && Same(ia.y(), ib.y()) && Same(ia.theta(), ib.theta());
}

bool SameOdometry(const Odometry& a, const Odometry& b) {
  if (!Same(a.start_time, b.start_time) || a.steps.size() != b.steps.size()) return false;
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    if (!SameStep(a.steps[k], b.steps[k])) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto odometry = priormap::slam::ParseOdometryCsv(text, "fuzz.csv");
  if (!odometry.ok()) {
    CheckLocated(odometry.diagnostics(), text, "fuzz.csv");
    return 0;
  }
  const Odometry& read = odometry.value();
  Check(!read.steps.empty(), "accepted odometry has steps");
  double previous = read.start_time;
  for (const MotionStep& step : read.steps) {
    Check(step.time > previous && step.dt > 0.0 && std::isfinite(step.dt) &&
              step.dt == step.time - previous,
          "steps are contiguous and in time order");
    Check(step.motion.index() == read.steps.front().motion.index(), "steps are of one kind");
    previous = step.time;
  }

  const std::string csv = priormap::slam::FormatOdometryCsv(read);
  const auto again = priormap::slam::ParseOdometryCsv(csv, "again.csv");
  Check(again.ok(), "written CSV is read back", again.ok() ? csv : again.error());
  Check(SameOdometry(again.value(), read), "CSV round trip keeps the steps", csv);
  Check(priormap::slam::FormatOdometryCsv(again.value()) == csv, "written CSV is a fixpoint", csv);
  return 0;
}
