// Tables of parameter inputs and the field errors they must give; JSON/CSV shapes of engine values.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "api/json_codec.h"

using nlohmann::json;
using namespace remesh;

namespace {

std::set<std::string> fields_of(const std::vector<FieldError>& errors) {
  std::set<std::string> s;
  for (const auto& e : errors) s.insert(e.field);
  return s;
}

}  // namespace

TEST_CASE("params_from_json: valid documents parse into Params", "[api][params]") {
  ParsedParams p = params_from_json(json::parse(
      R"({"emin":0.5,"emax":1.5,"iterations":7,"rings":3,"relax_every":2,"flip_factor":0.25,"run_all_iterations":true,"protect_tips":true,"keep_creases":true,"more_regular":true,"relax_dual":true,"weld":true})"));
  REQUIRE(p.ok());
  CHECK(p.params.e_min == 0.5);
  CHECK(p.params.e_max == 1.5);
  CHECK(p.params.iterations == 7);
  CHECK(p.params.rings == 3);
  CHECK(p.params.relax_every == 2);
  CHECK(p.params.flip_factor == 0.25);
  CHECK(p.params.run_all_iterations);
  CHECK(p.params.protect_tips);
  CHECK(p.params.keep_creases);
  CHECK(p.params.more_regular);
  CHECK(p.params.relax_dual);
  CHECK(p.weld);

  ParsedParams d = params_from_json(json::parse(R"({"emin":1,"emax":2,"iterations":5.0})"));
  REQUIRE(d.ok());
  CHECK(d.params.iterations == 5);
  CHECK(d.params.rings == Params{}.rings);
  CHECK_FALSE(d.params.protect_tips);
  CHECK_FALSE(d.params.keep_creases);
  CHECK_FALSE(d.params.more_regular);
  CHECK_FALSE(d.params.relax_dual);
  CHECK_FALSE(d.weld);
}

TEST_CASE("params_from_json: every bad field is reported", "[api][params]") {
  struct Row {
    const char* doc;
    std::set<std::string> fields;
  };
  const Row rows[] = {
      {R"({})", {"emin", "emax"}},
      {R"({"emin":1})", {"emax"}},
      {R"({"emin":"1","emax":2})", {"emin"}},
      {R"({"emin":1,"emax":2,"iterations":1.5})", {"iterations"}},
      {R"({"emin":1,"emax":2,"iterations":"ten","rings":[1]})", {"iterations", "rings"}},
      {R"({"emin":1,"emax":2,"run_all_iterations":"yes"})", {"run_all_iterations"}},
      {R"({"emin":1,"emax":2,"weld":1})", {"weld"}},
      {R"({"emin":1,"emax":2,"protect_tips":"true"})", {"protect_tips"}},
      {R"({"emin":1,"emax":2,"keep_creases":0})", {"keep_creases"}},
      {R"({"emin":1,"emax":2,"more_regular":"yes"})", {"more_regular"}},
      {R"({"emin":1,"emax":2,"relax_dual":"on"})", {"relax_dual"}},
      {R"({"emin":1,"emax":2,"flip_factor":null})", {"flip_factor"}},
      {R"({"emin":1,"emax":2,"iterations":99999999999})", {"iterations"}},
      {R"({"emin":1,"emax":2,"colour":"red"})", {"colour"}},
      {R"({"emax":true,"relax_every":{}})", {"emin", "emax", "relax_every"}},
      {R"([1,2])", {"params"}},
  };
  for (const Row& row : rows) {
    INFO(row.doc);
    ParsedParams p = params_from_json(json::parse(row.doc));
    CHECK(fields_of(p.errors) == row.fields);
    for (const auto& e : p.errors) CHECK_FALSE(e.message.empty());
  }
  // Too large for an integer says how large one may be ('must be an integer' alone misled).
  const ParsedParams big = params_from_json(json::parse(R"({"emin":1,"emax":2,"iterations":99999999999})"));
  REQUIRE(big.errors.size() == 1);
  CHECK(big.errors[0].message.find("at most 2147483647") != std::string::npos);
}

TEST_CASE("params_from_query: strings parse strictly", "[api][params]") {
  using Map = std::map<std::string, std::string>;
  ParsedParams ok = params_from_query(Map{{"emin", "1e-2"}, {"emax", " 0.03"}, {"iterations", "20"},
                                          {"run_all_iterations", ""}, {"weld", "off"}, {"format", "obj"}},
                                      {"format"});
  REQUIRE(ok.ok());
  CHECK(ok.params.e_min == 0.01);
  CHECK(ok.params.e_max == 0.03);
  CHECK(ok.params.iterations == 20);
  CHECK(ok.params.run_all_iterations);
  CHECK_FALSE(ok.weld);

  struct Row {
    Map values;
    std::set<std::string> fields;
  };
  const Row rows[] = {
      {{}, {"emin", "emax"}},
      {{{"emin", "abc"}, {"emax", "2"}}, {"emin"}},
      {{{"emin", "1"}, {"emax", "2x"}}, {"emax"}},
      {{{"emin", "nan"}, {"emax", "inf"}}, {"emin", "emax"}},
      {{{"emin", "1"}, {"emax", "2"}, {"iterations", "2.5"}}, {"iterations"}},
      {{{"emin", "1"}, {"emax", "2"}, {"rings", ""}}, {"rings"}},
      {{{"emin", "1"}, {"emax", "2"}, {"run_all_iterations", "maybe"}}, {"run_all_iterations"}},
      {{{"emin", "1"}, {"emax", "2"}, {"protect_tips", "2"}}, {"protect_tips"}},
      {{{"emin", "1"}, {"emax", "2"}, {"format", "obj"}}, {"format"}},  // not ignored here
      {{{"emin", "1"}, {"emax", "2"}, {"itrations", "3"}}, {"itrations"}},
  };
  for (const Row& row : rows) {
    std::ostringstream what;
    for (const auto& [k, v] : row.values) what << k << "=" << v << "&";
    INFO(what.str());
    CHECK(fields_of(params_from_query(row.values).errors) == row.fields);
  }
}

TEST_CASE("bond_min and bond_max give the interval as the dual's bonds", "[api][params]") {
  // Bonds b ask for edges b * sqrt(3) (equilateral triangles of side a have dual edges a / sqrt(3)).
  for (const auto& [lo, hi] : {std::pair{1.278, 1.562}, std::pair{0.05, 0.06}, std::pair{2.0, 3.0}}) {
    INFO(lo << " " << hi);
    ParsedParams j = params_from_json(json{{"bond_min", lo}, {"bond_max", hi}, {"iterations", 9}});
    REQUIRE(j.ok());
    REQUIRE(j.bonds);
    CHECK(j.bonds->min == lo);
    CHECK(j.bonds->max == hi);
    CHECK(j.params.e_min == Approx(lo * std::sqrt(3.0)).epsilon(1e-15));
    CHECK(j.params.e_max == Approx(hi * std::sqrt(3.0)).epsilon(1e-15));
    CHECK(j.params.iterations == 9);
    CHECK(validate_params(j).empty());
    using Map = std::map<std::string, std::string>;
    ParsedParams q = params_from_query(Map{{"bond_min", std::to_string(lo)}, {"bond_max", std::to_string(hi)}});
    REQUIRE(q.ok());
    CHECK(q.params.e_min == Approx(lo * std::sqrt(3.0)));
  }
  CHECK_FALSE(params_from_json(json{{"emin", 1}, {"emax", 2}}).bonds);

  // Each mistake names the fields the client gave, never an edge field it did not.
  struct Row {
    json doc;
    std::set<std::string> fields;
    const char* says;  // in the first error's message
  };
  const Row rows[] = {
      {{{"bond_min", 1}}, {"bond_max"}, "is required with bond_min"},
      {{{"bond_max", 1}}, {"bond_min"}, "is required with bond_max"},
      {{{"bond_min", 1}, {"bond_max", 2}, {"emin", 1}}, {"bond_min"}, "not both"},
      {{{"bond_max", 2}, {"emax", 3}, {"emin", 1}}, {"bond_max"}, "not both"},
      {{{"bond_min", 2}, {"bond_max", 1}}, {"bond_max"}, "must be greater than bond_min"},
      {{{"bond_min", -1}, {"bond_max", 1}}, {"bond_min"}, "> 0"},
      {{{"bond_min", "x"}, {"bond_max", 1}}, {"bond_min"}, "finite number"},
      {{{"bond_min", "x"}, {"rings", 9}}, {"bond_min", "bond_max", "rings"}, "finite number"},
      {{{"bond_min", 1}, {"bond_max", 2}, {"rings", 0}}, {"rings"}, "1..4"},
      // Each bad bond named, as emin and emax are (a bad bond_min hid bond_max's error).
      {{{"bond_min", "abc"}, {"bond_max", -1}}, {"bond_min", "bond_max"}, "finite number"},
      {{{"bond_min", 1}, {"bond_max", 1.5e308}}, {"bond_max"}, "too large"},
      {{{"emin", 1}}, {"emax"}, "or give bond_min and bond_max"},
  };
  for (const Row& row : rows) {
    INFO(row.doc.dump());
    ParsedParams p = params_from_json(row.doc);
    const std::vector<FieldError> errors = validate_params(p);
    CHECK(fields_of(errors) == row.fields);
    REQUIRE_FALSE(errors.empty());
    CHECK_THAT(errors.front().message, Catch::Contains(row.says));
  }
  // Edge errors said in bond terms: fields and words.
  const auto said = in_bond_terms({{"emax", "must be greater than emin"}, {"rings", "must be in 1..4"}});
  CHECK(said[0].field == "bond_max");
  CHECK(said[0].message == "must be greater than bond_min");
  CHECK(said[1].field == "rings");
  // Whole words only, in one pass (a new name is not renamed again).
  const auto words = renamed({{"emin", "emin, emin_x, x_emin, --emin and emax"}}, {{"emin", "emax"}, {"emax", "E"}});
  CHECK(words[0].field == "emax");
  CHECK(words[0].message == "emax, emin_x, x_emin, --emin and E");
}

TEST_CASE("Params and summaries map to the documented JSON names", "[api][json]") {
  Params p;
  p.e_min = 0.1;
  p.e_max = 0.2;
  p.protect_tips = true;
  p.keep_creases = true;
  p.more_regular = true;
  p.relax_dual = true;
  json j = p;
  for (const char* k : {"emin", "emax", "iterations", "rings", "relax_every", "flip_factor", "run_all_iterations",
                        "protect_tips", "keep_creases", "more_regular", "relax_dual"})
    CHECK(j.contains(k));
  CHECK(j["emin"] == 0.1);
  // Round trip through the parser.
  ParsedParams back = params_from_json(j);
  REQUIRE(back.ok());
  CHECK(back.params.e_max == 0.2);
  CHECK(back.params.protect_tips);
  CHECK(back.params.keep_creases);
  CHECK(back.params.more_regular);

  MeshSummary s;
  s.vertices = 12;
  s.faces = 20;
  s.edges = 30;
  s.components = 2;
  s.euler = 2;
  ComponentSummary closed;
  closed.closed = true;
  closed.genus = 1;
  ComponentSummary open;
  open.closed = false;
  s.per_component = {closed, open};
  s.bbox_max = Vec3(1, 2, 3);
  s.bbox_diagonal = std::sqrt(14.0);
  s.mean_edge = 0.5;
  json sj = summary_json(s, {Repair{"welded", 3, "3 vertices welded"}});
  CHECK(sj["vertices"] == 12);
  CHECK(sj["genus"] == json::array({1}));
  CHECK(sj["bbox"]["max"] == json::array({1.0, 2.0, 3.0}));
  CHECK(sj["bbox"]["diagonal"] == s.bbox_diagonal);
  CHECK(sj["edge_length"]["mean"] == 0.5);
  for (const char* k : {"boundary_loops", "boundary_edges", "euler", "area", "components", "faces", "edges"})
    CHECK(sj.contains(k));
  REQUIRE(sj["repairs"].size() == 1);
  CHECK(sj["repairs"][0]["kind"] == "welded");
  CHECK(sj["repairs"][0]["count"] == 3);
}

TEST_CASE("IterationStats: JSON round trip and CSV in struct order", "[api][stats]") {
  IterationStats s;
  s.iteration = 3;
  s.vertices = 100;
  s.edges = 300;
  s.mean = 0.1;
  s.deviation = 1e-7;
  s.regular_percent = 87.5;
  s.small = 4;
  s.big = 5;
  s.inside_fraction = 0.9;
  s.splits = 6;
  s.collapses = 7;
  s.flips = 8;
  s.seconds = 0.015625;
  s.max_projection_distance = 2.5e-3;
  json j = s;
  CHECK(j.size() == 14);
  IterationStats back = j.get<IterationStats>();
  CHECK(back.iteration == 3);
  CHECK(back.deviation == 1e-7);
  CHECK(back.flips == 8);
  CHECK(back.max_projection_distance == 2.5e-3);

  const std::string header = stats_csv_header();
  CHECK(header ==
        "iteration,vertices,edges,mean,deviation,regular_percent,small,big,inside_fraction,splits,collapses,flips,"
        "seconds,max_projection_distance");
  CHECK(stats_csv_row(s) == "3,100,300,0.1,1e-07,87.5,4,5,0.9,6,7,8,0.015625,0.0025");
  std::string csv = stats_to_csv({s, s});
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 3);
  CHECK(format_double(0.1) == "0.1");
  CHECK(format_double(std::nan("")) == "null");
}
