#include <algorithm>

#include <priormap/core/binary_io.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/sonar_likelihood.hpp>
#include <priormap/prf/sonar_mapping.hpp>

namespace priormap::prf {
namespace {

// Where the axis of a reading that echoed meets its arc.
Vec2 ArcPoint(const SonarReading& r, double along) {
  return r.cone.origin + along * r.cone.axis;
}

}  // namespace

std::uint64_t SonarDataFingerprint(const SonarData& data, const SonarModel& model) {
  BinaryWriter out;
  out.Put(data.max_range);
  out.Put<std::uint64_t>(data.sensors.size());
  for (const Vec2& s : data.sensors) {
    out.Put(s.x());
    out.Put(s.y());
  }
  out.Put<std::uint64_t>(data.readings.size());
  for (const SonarReading& r : data.readings) {
    for (double v : {r.cone.origin.x(), r.cone.origin.y(), r.cone.axis.x(), r.cone.axis.y(),
                     r.cone.half_spread, r.cone.max_range, r.range})
      out.Put(v);
    out.Put<std::uint8_t>(r.max_reading ? 1 : 0);
    out.Put<std::int32_t>(r.sensor);
  }
  for (const auto& [name, member] : kSonarModelParameters) out.Put(model.*member);
  return Fnv1a64(out.bytes());
}

MappingData SonarMappingData(std::shared_ptr<const SonarData> data, const SonarModel& model,
                             const MappingOptions& options) {
  MappingData d;
  d.window = WindowAround(*data, options.margin);
  std::vector<std::size_t> echoes;
  for (std::size_t i = 0; i < data->readings.size(); ++i) {
    const SonarReading& r = data->readings[i];
    if (r.max_reading) continue;
    echoes.push_back(i);
    const Vec2 p = ArcPoint(r, r.range);
    if (d.window.ContainsInterior(p)) d.guide_points.push_back(p);
  }
  const int pairs = std::max(1, options.trace_points / 2);
  for (int k = 0; !echoes.empty() && options.trace_points > 0 && k < pairs; ++k) {
    const SonarReading& r = data->readings[echoes[static_cast<std::size_t>(k) * echoes.size() /
                                                  static_cast<std::size_t>(pairs)]];
    for (double along : {0.5 * r.range, r.range + 0.1}) {
      const Vec2 p = ArcPoint(r, along);
      if (d.window.ContainsInterior(p)) d.trace_points.push_back(p);
    }
  }
  // The options' part of the laser fingerprint, with no beams, is the options' hash.
  d.data_fingerprint = SonarDataFingerprint(*data, model);
  d.fingerprint = Fnv1a64(std::to_string(d.data_fingerprint) + ":" +
                          std::to_string(RunFingerprint(LaserData{}, options)));
  d.make_data_term = [data, model] { return std::make_unique<SonarLikelihood>(data, model); };
  d.make_thinned_data_term = [data, model](int stride, int phase) {
    return std::make_unique<SonarLikelihood>(ThinnedSonarData(*data, stride, phase), model);
  };
  return d;
}

std::shared_ptr<const SonarData> ThinnedSonarData(const SonarData& data, int stride, int phase) {
  auto thinned = std::make_shared<SonarData>();
  thinned->sensors = data.sensors;  // every transducer stays in white
  thinned->max_range = data.max_range;
  for (std::size_t i = 0; i < data.readings.size(); ++i)
    if (KeptByThinning(i, stride, phase)) thinned->readings.push_back(data.readings[i]);
  return thinned;
}

}  // namespace priormap::prf
