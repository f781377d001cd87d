#include <cmath>

#include <tbb/parallel_for.h>

#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/prf/arak.hpp>
#include <priormap/prf/replica_exchange.hpp>

namespace priormap::prf {

std::vector<double> GeometricLadder(int replicas, double top) {
  PRIORMAP_CHECK(replicas >= 1, "at least one replica");
  PRIORMAP_CHECK(std::isfinite(top) && (replicas == 1 ? top >= 1.0 : top > 1.0),
                 "the replicas' top temperature must be finite and above 1");
  std::vector<double> ladder(static_cast<std::size_t>(replicas), 1.0);
  for (int k = 1; k < replicas; ++k)
    ladder[static_cast<std::size_t>(k)] = std::pow(top, static_cast<double>(k) / (replicas - 1));
  return ladder;
}

double TemperedLogDensity(const PrfSampler& sampler) {
  return sampler.LogPosterior() - ArakLogMeasure(sampler.coloring().stats(), sampler.options().p);
}

double LogSwapRatio(double a, double temperature_a, double b, double temperature_b) {
  // π_a(y) π_b(x) / (π_a(x) π_b(y)) with π_T(χ) ∝ λ(dχ) exp(h(χ)/T): λ cancels.
  return (b - a) / temperature_a + (a - b) / temperature_b;
}

std::vector<double> SwapRates(const std::vector<SwapCounter>& swaps) {
  std::vector<double> rates;
  for (const SwapCounter& counter : swaps) rates.push_back(counter.rate());
  return rates;
}

ReplicaLadder::ReplicaLadder(std::vector<std::unique_ptr<PrfSampler>> replicas,
                             std::vector<double> ladder, std::uint64_t seed,
                             std::vector<SwapCounter> swaps)
    : replicas_(std::move(replicas)),
      ladder_(std::move(ladder)),
      seed_(seed),
      swaps_(std::move(swaps)) {
  PRIORMAP_CHECK(!replicas_.empty() && replicas_.size() == ladder_.size(),
                 "one temperature per replica");
  PRIORMAP_CHECK(ladder_.front() == 1.0, "the ladder starts at temperature 1");
  for (std::size_t k = 1; k < ladder_.size(); ++k)
    PRIORMAP_CHECK(ladder_[k] > ladder_[k - 1], "the ladder's temperatures increase");
  if (swaps_.empty()) swaps_.resize(ladder_.size() - 1);
  PRIORMAP_CHECK(swaps_.size() == ladder_.size() - 1, "one swap counter per adjacent pair");
  for (const auto& replica : replicas_)
    PRIORMAP_CHECK(replica->steps() == replicas_.front()->steps(),
                   "the replicas of a ladder have taken the same number of steps");
  set_scale(1.0);
}

void ReplicaLadder::set_scale(double scale) {
  scale_ = scale;
  for (std::size_t k = 0; k < replicas_.size(); ++k) replicas_[k]->set_temperature(temperature(k));
}

std::vector<const PrfSampler*> ReplicaLadder::hot() const {
  std::vector<const PrfSampler*> hot;
  for (std::size_t k = 1; k < replicas_.size(); ++k) hot.push_back(replicas_[k].get());
  return hot;
}

void ReplicaLadder::Run(std::uint64_t steps) {
  tbb::parallel_for(std::size_t{0}, replicas_.size(),
                    [&](std::size_t k) { replicas_[k]->Run(steps); });
}

void ReplicaLadder::Exchange(std::uint64_t round) {
  Rng rng = Rng::ForStream(seed_, round);
  // Two replicas make one pair, offered every round.
  const std::size_t first = replicas_.size() > 2 ? round % 2 : 0;
  for (std::size_t k = first; k + 1 < replicas_.size(); k += 2) {
    SwapCounter& counter = swaps_[k];
    ++counter.proposed;
    const double log_ratio =
        LogSwapRatio(TemperedLogDensity(*replicas_[k]), temperature(k),
                     TemperedLogDensity(*replicas_[k + 1]), temperature(k + 1));
    // The uniform is drawn whatever the ratio, so that each pair's decision uses its own draw.
    const double u = rng.Uniform();
    if (log_ratio >= 0.0 || u < std::exp(log_ratio)) {
      std::swap(replicas_[k], replicas_[k + 1]);
      replicas_[k]->set_temperature(temperature(k));
      replicas_[k + 1]->set_temperature(temperature(k + 1));
      ++counter.accepted;
    }
  }
}

std::unique_ptr<PrfSampler> ReplicaLadder::TakeCold() && {
  return std::move(replicas_.front());
}

std::unique_ptr<PrfSampler> ReplicaLadder::TakeBest() && {
  std::size_t best = 0;
  for (std::size_t k = 1; k < replicas_.size(); ++k)
    if (replicas_[k]->LogPosterior() > replicas_[best]->LogPosterior()) best = k;
  replicas_[best]->set_temperature(temperature(0));
  return std::move(replicas_[best]);
}

}  // namespace priormap::prf
