#pragma once
/// Latent structures and their part-of relation (Parsley & Julier, Sec. III and Fig. 2): every
/// structure instance belongs to a structure class, and classes form a hierarchy (a wall is part
/// of a building, a building of a city). Features come from instances at any level; a relation
/// known only at an upper level ("the point is on some wall of this building") is a mixture over
/// the instances below it (eq. 3; association_hypotheses.hpp infers it, pseudo_observation.hpp
/// applies it).
///
/// For a prior map: one building instance per GeoJSON feature and one wall instance per segment,
/// each wall part of its feature's building (the paper: the wall instance is the one "defined in
/// terms of producing" its line). A wall that buildings share (PriorSegment::shared_with) is one
/// wall instance in each of them, all producing the one segment: each building's side of it.

#include <optional>
#include <string>
#include <vector>

namespace priormap::slam {

struct PriorMap;

class StructureHierarchy {
 public:
  /// A class one level below `parent` (nullopt: a top-level class). Returns its index.
  int AddClass(std::string name, std::optional<int> parent = std::nullopt);
  /// An instance of `structure_class`, part of `parent`, which must be an instance of the class's
  /// parent class (and absent for a top-level class). Returns its index.
  int AddInstance(int structure_class, std::optional<int> parent = std::nullopt);

  [[nodiscard]] int NumClasses() const { return static_cast<int>(classes_.size()); }
  [[nodiscard]] int NumInstances() const { return static_cast<int>(instances_.size()); }
  [[nodiscard]] const std::string& ClassName(int structure_class) const;
  [[nodiscard]] int ClassOf(int instance) const;
  [[nodiscard]] std::optional<int> ParentOf(int instance) const;

  /// Whether `instance` is part of `whole`, directly or through intermediate levels (an
  /// instance is not part of itself).
  [[nodiscard]] bool IsPartOf(int instance, int whole) const;
  /// The instance of `structure_class` that `instance` is part of, if any.
  [[nodiscard]] std::optional<int> AncestorOfClass(int instance, int structure_class) const;
  /// The instances of `structure_class` that are part of `whole`, in index order.
  [[nodiscard]] std::vector<int> PartsOf(int whole, int structure_class) const;

 private:
  struct Class {
    std::string name;
    std::optional<int> parent;
  };
  struct Instance {
    int structure_class = -1;
    std::optional<int> parent;
    std::vector<int> children;
  };
  void CheckInstance(int instance) const;

  std::vector<Class> classes_;
  std::vector<Instance> instances_;
};

/// The hierarchy of a prior map: classes building and wall (wall part of building).
struct PriorMapStructures {
  StructureHierarchy hierarchy;
  int building_class = -1;
  int wall_class = -1;
  std::vector<int> building_instance;  ///< per PriorMap::buildings
  /// Per PriorMap::segments: its wall instance in its `building`, else in the first building it
  /// is shared with, else one of no building.
  std::vector<int> wall_instance;
  /// Per PriorMap::segments: its wall instances in the other buildings it is shared with.
  std::vector<std::vector<int>> shared_wall_instances;
  std::vector<int> segment_of_wall;  ///< per hierarchy instance: its segment, -1 for buildings
  std::vector<int> building_index;   ///< per hierarchy instance: its building, -1 for walls

  /// The building of `segment`'s wall_instance (an index into PriorMap::buildings), if any.
  [[nodiscard]] std::optional<int> BuildingOf(int segment) const;
  /// Every building `segment` is part of, ascending (more than one: a wall they share).
  [[nodiscard]] std::vector<int> BuildingsOf(int segment) const;
  /// The segments of building `building` (an index into PriorMap::buildings).
  [[nodiscard]] std::vector<int> SegmentsOf(int building) const;
};

/// Segments without a building (building < 0 and no shared_with) are walls of no building.
[[nodiscard]] PriorMapStructures StructuresOf(const PriorMap& map);

}  // namespace priormap::slam
