#pragma once
/// The black (occupied) area of a coloring and its change under an edit: what a prior that
/// prefers free space needs (Paskin & Thrun, Sec. 4: "the prior potential can be augmented with
/// cost functions that prefer ... maps with more empty space"; SamplerOptions::free_space).

#include <optional>

#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

/// The area of the window's black points, from the coloring's faces.
[[nodiscard]] double BlackArea(const Coloring& coloring);

/// The change of BlackArea if `edit` (which coloring.Evaluate accepted) were applied, when the
/// region it flips is a simple polygon holding nothing of the coloring (no vertex, no edge):
/// that region is then of one colour, and the change is plus or minus its area. nullopt for any
/// other edit (a self-crossing region, or one with structure inside), whose change would need
/// the faces it cuts. An edit and its reverse flip the same region, so both or neither qualify.
[[nodiscard]] std::optional<double> BlackAreaChange(const Coloring& coloring, const Edit& edit);

}  // namespace priormap::prf
