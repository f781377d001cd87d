#include <algorithm>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/structure_hierarchy.hpp>

namespace priormap::slam {

int StructureHierarchy::AddClass(std::string name, std::optional<int> parent) {
  PRIORMAP_CHECK(!parent || (0 <= *parent && *parent < NumClasses()),
                 fmt::format("parent class {} of '{}' does not exist", *parent, name));
  classes_.push_back({std::move(name), parent});
  return NumClasses() - 1;
}

int StructureHierarchy::AddInstance(int structure_class, std::optional<int> parent) {
  PRIORMAP_CHECK(0 <= structure_class && structure_class < NumClasses(),
                 fmt::format("structure class {} does not exist", structure_class));
  const std::optional<int> parent_class = classes_[structure_class].parent;
  if (parent) {
    CheckInstance(*parent);
    PRIORMAP_CHECK(parent_class && instances_[*parent].structure_class == *parent_class,
                   fmt::format("an instance of '{}' cannot be part of an instance of '{}'",
                               classes_[structure_class].name,
                               classes_[instances_[*parent].structure_class].name));
  }
  const int index = NumInstances();
  instances_.push_back({structure_class, parent, {}});
  if (parent) instances_[*parent].children.push_back(index);
  return index;
}

void StructureHierarchy::CheckInstance(int instance) const {
  PRIORMAP_CHECK(0 <= instance && instance < NumInstances(),
                 fmt::format("structure instance {} does not exist", instance));
}

const std::string& StructureHierarchy::ClassName(int structure_class) const {
  PRIORMAP_CHECK(0 <= structure_class && structure_class < NumClasses(),
                 fmt::format("structure class {} does not exist", structure_class));
  return classes_[structure_class].name;
}

int StructureHierarchy::ClassOf(int instance) const {
  CheckInstance(instance);
  return instances_[instance].structure_class;
}

std::optional<int> StructureHierarchy::ParentOf(int instance) const {
  CheckInstance(instance);
  return instances_[instance].parent;
}

bool StructureHierarchy::IsPartOf(int instance, int whole) const {
  CheckInstance(whole);
  for (std::optional<int> up = ParentOf(instance); up; up = instances_[*up].parent) {
    if (*up == whole) return true;
  }
  return false;
}

std::optional<int> StructureHierarchy::AncestorOfClass(int instance, int structure_class) const {
  for (std::optional<int> up = ParentOf(instance); up; up = instances_[*up].parent) {
    if (instances_[*up].structure_class == structure_class) return up;
  }
  return std::nullopt;
}

std::vector<int> StructureHierarchy::PartsOf(int whole, int structure_class) const {
  CheckInstance(whole);
  std::vector<int> parts;
  std::vector<int> stack = instances_[whole].children;
  while (!stack.empty()) {
    const int next = stack.back();
    stack.pop_back();
    if (instances_[next].structure_class == structure_class) parts.push_back(next);
    stack.insert(stack.end(), instances_[next].children.begin(), instances_[next].children.end());
  }
  std::sort(parts.begin(), parts.end());
  return parts;
}

std::optional<int> PriorMapStructures::BuildingOf(int segment) const {
  const auto wall = wall_instance.at(static_cast<std::size_t>(segment));
  const std::optional<int> building = hierarchy.AncestorOfClass(wall, building_class);
  if (!building) return std::nullopt;
  return building_index[static_cast<std::size_t>(*building)];
}

std::vector<int> PriorMapStructures::BuildingsOf(int segment) const {
  std::vector<int> buildings;
  if (const std::optional<int> own = BuildingOf(segment)) buildings.push_back(*own);
  for (int wall : shared_wall_instances.at(static_cast<std::size_t>(segment))) {
    buildings.push_back(building_index[static_cast<std::size_t>(*hierarchy.ParentOf(wall))]);
  }
  std::sort(buildings.begin(), buildings.end());
  return buildings;
}

std::vector<int> PriorMapStructures::SegmentsOf(int building) const {
  std::vector<int> segments;
  for (int wall :
       hierarchy.PartsOf(building_instance.at(static_cast<std::size_t>(building)), wall_class)) {
    segments.push_back(segment_of_wall[wall]);
  }
  return segments;
}

PriorMapStructures StructuresOf(const PriorMap& map) {
  PriorMapStructures out;
  out.building_class = out.hierarchy.AddClass("building");
  out.wall_class = out.hierarchy.AddClass("wall", out.building_class);
  for (std::size_t b = 0; b < map.buildings.size(); ++b) {
    out.building_instance.push_back(out.hierarchy.AddInstance(out.building_class));
    out.segment_of_wall.push_back(-1);
    out.building_index.push_back(static_cast<int>(b));
  }
  const auto add_wall = [&](std::size_t segment, std::optional<int> building) {
    std::optional<int> parent;
    if (building) parent = out.building_instance[static_cast<std::size_t>(*building)];
    out.segment_of_wall.push_back(static_cast<int>(segment));
    out.building_index.push_back(-1);
    return out.hierarchy.AddInstance(out.wall_class, parent);
  };
  for (std::size_t s = 0; s < map.segments.size(); ++s) {
    const PriorSegment& segment = map.segments[s];
    std::vector<int> buildings;
    if (segment.building >= 0) buildings.push_back(segment.building);
    for (int other : segment.shared_with) {
      PRIORMAP_CHECK(other >= 0, fmt::format("segment {} is shared with building {}", s, other));
      if (std::find(buildings.begin(), buildings.end(), other) == buildings.end())
        buildings.push_back(other);
    }
    for (int building : buildings) {
      PRIORMAP_CHECK(building < static_cast<int>(map.buildings.size()),
                     fmt::format("segment {} is part of building {}, but the map has {}", s,
                                 building, map.buildings.size()));
    }
    out.wall_instance.push_back(
        add_wall(s, buildings.empty() ? std::nullopt : std::optional<int>(buildings.front())));
    out.shared_wall_instances.emplace_back();
    for (std::size_t k = 1; k < buildings.size(); ++k)
      out.shared_wall_instances.back().push_back(add_wall(s, buildings[k]));
  }
  return out;
}

}  // namespace priormap::slam
