#include "chains_status.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace priormap::app {

namespace {

// A thinned stage's log posterior is of a fraction of the data, an order of magnitude below the
// full data's; saying so keeps the jump at the stage's end from reading as a failure. Where the
// chains' stages differ, each value carries the short form, to keep the line on one row.
std::string ThinnedNote(int data_stride, bool short_form) {
  if (data_stride <= 1) return "";
  return short_form ? fmt::format(" (on 1/{})", data_stride)
                    : fmt::format(" (on 1/{} of the readings)", data_stride);
}

}  // namespace

std::string ChainsLogPosteriors(const std::vector<prf::ChainProgress>& chains) {
  std::vector<int> strides;
  for (const prf::ChainProgress& chain : chains)
    if (chain.reported) strides.push_back(chain.data_stride);
  std::ranges::sort(strides);
  strides.erase(std::unique(strides.begin(), strides.end()), strides.end());
  if (strides.empty()) return "";
  const bool one_stage = strides.size() == 1;
  std::vector<std::string> parts;
  if (chains.size() <= 4) {
    for (const prf::ChainProgress& chain : chains)
      parts.push_back(chain.reported ? fmt::format("{:.1f}{}", chain.log_posterior,
                                                   one_stage ? ""
                                                             : ThinnedNote(chain.data_stride,
                                                                           /*short_form=*/true))
                                     : "...");
    return fmt::format("log posterior{} {}{}", chains.size() == 1 ? "" : "s",
                       fmt::join(parts, ", "),
                       one_stage ? ThinnedNote(strides.front(), /*short_form=*/false) : "");
  }
  std::size_t reported = 0;
  for (const int stride : strides) {
    std::vector<double> values;
    for (const prf::ChainProgress& chain : chains)
      if (chain.reported && chain.data_stride == stride) values.push_back(chain.log_posterior);
    reported += values.size();
    const std::string note = ThinnedNote(stride, /*short_form=*/!one_stage);
    parts.push_back(values.size() == 1
                        ? fmt::format("{:.1f}{}", values.front(), note)
                        : fmt::format("{:.1f} to {:.1f} over {} chains{}", std::ranges::min(values),
                                      std::ranges::max(values), values.size(), note));
  }
  const std::string waiting =
      reported < chains.size() ? fmt::format("; {} of {} chains reported", reported, chains.size())
                               : "";
  return fmt::format("log posteriors {}{}", fmt::join(parts, "; "), waiting);
}

std::string MappingState(const prf::MappingProgress& progress) {
  if (!progress.annealing) return ChainsLogPosteriors(progress.chains);
  const prf::AnnealingProgress& a = *progress.annealing;
  return fmt::format("annealing chain {} at T {:.3g}, log posterior {:.1f}", a.chain, a.temperature,
                     a.log_posterior);
}

double RecentRate::Add(double seconds, std::uint64_t steps) {
  reports_.push_back({seconds, steps});
  while (reports_.size() > 1 && reports_[1].seconds <= seconds - window_s_) reports_.pop_front();
  const Report& since = reports_.front();
  const double elapsed = seconds - since.seconds;
  return elapsed > 0.0 ? static_cast<double>(steps - since.steps) / elapsed : 0.0;
}

}  // namespace priormap::app
