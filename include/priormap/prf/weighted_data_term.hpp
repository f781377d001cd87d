#pragma once
/// A data term whose log-likelihood is another's times a whole number: a thinned term weighed up
/// by its stride is an unbiased estimate of the full data's (MappingOptions::thinned_weighed).
/// The weight is whole so that the fixed-point sums stay exact (data_term.hpp).
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <priormap/prf/data_term.hpp>

namespace priormap::prf {

class WeightedDataTerm final : public DataTerm {
 public:
  /// Precondition: inner is set and weight ≥ 1.
  WeightedDataTerm(std::unique_ptr<DataTerm> inner, int weight);

  std::optional<std::string> Reset(const Coloring& coloring) override {
    return inner_->Reset(coloring);
  }
  std::optional<FixedLogLik> Evaluate(const Coloring& coloring, const Edit& edit) override {
    const auto change = inner_->Evaluate(coloring, edit);
    if (!change) return std::nullopt;
    return *change * weight_;
  }
  void Commit(std::span<const EdgeId> added_edges) override { inner_->Commit(added_edges); }
  [[nodiscard]] FixedLogLik log_likelihood() const override {
    return inner_->log_likelihood() * weight_;
  }
  [[nodiscard]] FixedLogLik RecomputeLogLikelihood(const Coloring& coloring) const override {
    return inner_->RecomputeLogLikelihood(coloring) * weight_;
  }
  [[nodiscard]] std::optional<std::string> FindInconsistency(
      const Coloring& coloring) const override {
    return inner_->FindInconsistency(coloring);
  }
  [[nodiscard]] std::unique_ptr<DataTerm> Clone() const override {
    return std::make_unique<WeightedDataTerm>(inner_->Clone(), weight_);
  }

 private:
  std::unique_ptr<DataTerm> inner_;
  int weight_;
};

}  // namespace priormap::prf
