// MappingData::data_fingerprint, by which `priormap prf rhat` decides that runs sample one
// likelihood: equal for equal readings and data model whatever the sampler's options, different
// when one reading or one model parameter differs.
#include <memory>

#include <gtest/gtest.h>

#include <priormap/prf/mapping.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_mapping.hpp>
#include <priormap/prf/sonar_model.hpp>

#include "mapping_testing.hpp"

namespace priormap::prf {
namespace {

MappingOptions Options(double p, std::uint64_t seed) {
  MappingOptions options;
  options.sampler.p = p;
  options.seed = seed;
  return options;
}

TEST(DataFingerprint, OfLaserDataIgnoresTheSamplerAndSeesEveryBeamAndTheModel) {
  const auto room = RoomData();
  const MappingData a = LaserMappingData(room, Options(0.5, 1));
  const MappingData b = LaserMappingData(room, Options(2.0, 9));
  EXPECT_EQ(a.data_fingerprint, b.data_fingerprint);
  EXPECT_NE(a.fingerprint, b.fingerprint);  // the run's own fingerprint does see the options

  auto moved = std::make_shared<LaserData>(*room);
  moved->beams[moved->beams.size() / 2].range += 1e-3;
  EXPECT_NE(LaserMappingData(moved, Options(0.5, 1)).data_fingerprint, a.data_fingerprint);
  MappingOptions other_model = Options(0.5, 1);
  other_model.model.sigma *= 2.0;
  EXPECT_NE(LaserMappingData(room, other_model).data_fingerprint, a.data_fingerprint);
}

TEST(DataFingerprint, OfSonarDataIgnoresTheSamplerAndSeesEveryReadingAndTheModel) {
  auto data = std::make_shared<SonarData>();
  data->max_range = 5.0;
  data->sensors = {Vec2(0.0, 0.0)};
  for (int k = 0; k < 8; ++k) {
    SonarReading r;
    r.cone.origin = Vec2(0.0, 0.0);
    r.cone.axis = Vec2(1.0, 0.0);
    r.cone.half_spread = 0.17;
    r.cone.max_range = 5.0;
    r.range = 1.0 + 0.25 * k;
    data->readings.push_back(r);
  }
  const SonarModel model;
  const MappingData a = SonarMappingData(data, model, Options(0.5, 1));
  const MappingData b = SonarMappingData(data, model, Options(2.0, 9));
  EXPECT_EQ(a.data_fingerprint, b.data_fingerprint);
  EXPECT_EQ(a.data_fingerprint, SonarDataFingerprint(*data, model));
  EXPECT_NE(a.fingerprint, b.fingerprint);

  auto missed = std::make_shared<SonarData>(*data);
  missed->readings[3].max_reading = true;
  EXPECT_NE(SonarMappingData(missed, model, Options(0.5, 1)).data_fingerprint, a.data_fingerprint);
  SonarModel other = model;
  other.sigma_relative *= 2.0;
  EXPECT_NE(SonarMappingData(data, other, Options(0.5, 1)).data_fingerprint, a.data_fingerprint);
}

}  // namespace
}  // namespace priormap::prf
