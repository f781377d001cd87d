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
/// region it flips holds nothing of the coloring (no vertex, no edge) and is a simple polygon
/// (then of one colour: the change is plus or minus its area) or a bow tie, a ring crossing
/// itself once (a vertex moved past the line of its neighbours: two simple lobes, each of one
/// colour, the change the sum of their ± areas). nullopt for any other edit (more crossings,
/// or structure inside), whose change would need the faces it cuts. An edit and its reverse flip
/// the same region, so both or neither qualify.
[[nodiscard]] std::optional<double> BlackAreaChange(const Coloring& coloring, const Edit& edit);

}  // namespace priormap::prf
