#include <priormap/core/check.hpp>
#include <priormap/prf/weighted_data_term.hpp>

namespace priormap::prf {

WeightedDataTerm::WeightedDataTerm(std::unique_ptr<DataTerm> inner, int weight)
    : inner_(std::move(inner)), weight_(weight) {
  PRIORMAP_CHECK(inner_ != nullptr, "a weighted data term needs a data term to weigh");
  PRIORMAP_CHECK(weight_ >= 1, "a data term's weight must be a whole number of at least 1");
}

}  // namespace priormap::prf
