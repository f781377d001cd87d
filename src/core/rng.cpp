#include <cmath>
#include <limits>
#include <sstream>

#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>

namespace priormap {

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

Rng Rng::ForStream(std::uint64_t seed, std::uint64_t stream) {
  return Rng(SplitMix64(SplitMix64(seed) ^ SplitMix64(stream + 0x632be59bd9b4e019ULL)));
}

void Rng::Save(BinaryWriter& out) const {
  std::ostringstream state;
  state << engine_;
  out.PutString(state.str());
  out.Put(spare_normal_);
  out.Put<std::uint8_t>(has_spare_normal_ ? 1 : 0);
}

void Rng::Load(BinaryReader& in) {
  std::istringstream state(in.GetString());
  state >> engine_;
  // An all-zero state is a fixed point of the Mersenne Twister (only zeros, and Normal() would
  // never return): no seeded generator reaches it.
  std::mt19937_64 zero_probe = engine_;
  bool all_zero = true;
  for (int i = 0; i < 624 && all_zero; ++i) all_zero = zero_probe() == 0;
  if (state.fail() || all_zero) in.Fail("an invalid random generator state");
  spare_normal_ = in.Get<double>();
  has_spare_normal_ = in.Get<std::uint8_t>() != 0;
}

double Rng::Uniform() {
  // 53 random bits -> a double in [0, 1); std::generate_canonical's result is not specified
  // exactly enough to be the same across standard libraries.
  return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
}

double Rng::Normal() {
  if (has_spare_normal_) {
    has_spare_normal_ = false;
    return spare_normal_;
  }
  double u, v, s;
  do {
    u = 2.0 * Uniform() - 1.0;
    v = 2.0 * Uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_normal_ = v * factor;
  has_spare_normal_ = true;
  return u * factor;
}

std::uint64_t Rng::UniformIndex(std::uint64_t n) {
  PRIORMAP_CHECK(n > 0, "UniformIndex needs n > 0");
  // Rejection sampling removes the modulo bias.
  const std::uint64_t limit =
      std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t x;
  do {
    x = engine_();
  } while (x >= limit);
  return x % n;
}

}  // namespace priormap
