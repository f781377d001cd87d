#pragma once
/// Random numbers with explicit seeds. Every random process in priormap takes an Rng (or a
/// seed) from its caller; there is no global generator. The engine and the normal sampler are
/// specified exactly (not std::normal_distribution), so a seed gives the same numbers with any
/// standard library.

#include <cstdint>
#include <random>

#include <priormap/core/binary_io.hpp>

namespace priormap {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  /// An independent stream for sub-task `stream` of a process seeded with `seed` (for
  /// parallel loops whose result must not depend on the number of threads).
  static Rng ForStream(std::uint64_t seed, std::uint64_t stream);

  /// Uniform in [0, 1).
  double Uniform();
  /// Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  /// Standard normal (Marsaglia's polar method).
  double Normal();
  double Normal(double mean, double stddev) { return mean + stddev * Normal(); }
  /// True with probability p.
  bool Bernoulli(double p) { return Uniform() < p; }
  /// Uniform integer in [0, n). Precondition: n > 0.
  std::uint64_t UniformIndex(std::uint64_t n);

  std::mt19937_64& engine() { return engine_; }

  /// The whole state (engine and the normal sampler's spare), so that a restored generator
  /// continues the same stream.
  void Save(BinaryWriter& out) const;
  void Load(BinaryReader& in);

 private:
  std::mt19937_64 engine_;
  double spare_normal_ = 0.0;
  bool has_spare_normal_ = false;
};

/// SplitMix64: a bijective mixer, used to derive stream seeds.
[[nodiscard]] std::uint64_t SplitMix64(std::uint64_t x);

}  // namespace priormap
