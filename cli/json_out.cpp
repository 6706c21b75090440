/// \file json_out.cpp
#include "json_out.h"

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

namespace remesh::cli {
namespace {

using nlohmann::json;

json vec3(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

json component_json(const ComponentSummary& c) {
  return {{"vertices", c.vertices}, {"faces", c.faces},   {"edges", c.edges},
          {"boundary_loops", c.boundary_loops}, {"euler", c.euler}, {"genus", c.genus},
          {"closed", c.closed}};
}

json row_json(const IterationStats& s) {
  return {{"iteration", s.iteration},
          {"vertices", s.vertices},
          {"edges", s.edges},
          {"mean", s.mean},
          {"deviation", s.deviation},
          {"regular_percent", s.regular_percent},
          {"small", s.small},
          {"big", s.big},
          {"inside_fraction", s.inside_fraction},
          {"splits", s.splits},
          {"collapses", s.collapses},
          {"flips", s.flips},
          {"seconds", s.seconds},
          {"max_projection_distance", s.max_projection_distance}};
}

}  // namespace

std::string info_json(const std::string& file, Format format, const MeshSummary& s,
                      const std::vector<Repair>& repairs) {
  json components = json::array();
  for (const auto& c : s.per_component) components.push_back(component_json(c));
  json fixes = json::array();
  for (const auto& r : repairs) fixes.push_back({{"kind", r.kind}, {"count", r.count}, {"detail", r.detail}});
  json out = {{"file", file},
              {"format", std::string(format_name(format))},
              {"vertices", s.vertices},
              {"faces", s.faces},
              {"edges", s.edges},
              {"components", s.components},
              {"boundary_loops", s.boundary_loops},
              {"boundary_edges", s.boundary_edges},
              {"euler", s.euler},
              {"per_component", components},
              {"bbox_min", vec3(s.bbox_min)},
              {"bbox_max", vec3(s.bbox_max)},
              {"bbox_diagonal", s.bbox_diagonal},
              {"mean_edge", s.mean_edge},
              {"min_edge", s.min_edge},
              {"max_edge", s.max_edge},
              {"area", s.area},
              {"repairs", fixes}};
  return out.dump(2);
}

std::string stats_json(const std::vector<IterationStats>& rows) {
  json out = json::array();
  for (const auto& r : rows) out.push_back(row_json(r));
  return out.dump(2);
}

std::string stats_csv(const std::vector<IterationStats>& rows) {
  std::ostringstream s;
  s.precision(10);
  s << "iteration,vertices,edges,mean,deviation,regular_percent,small,big,inside_fraction,splits,"
       "collapses,flips,seconds,max_projection_distance\n";
  for (const auto& r : rows)
    s << r.iteration << ',' << r.vertices << ',' << r.edges << ',' << r.mean << ',' << r.deviation << ','
      << r.regular_percent << ',' << r.small << ',' << r.big << ',' << r.inside_fraction << ',' << r.splits
      << ',' << r.collapses << ',' << r.flips << ',' << r.seconds << ',' << r.max_projection_distance << '\n';
  return s.str();
}

}  // namespace remesh::cli
