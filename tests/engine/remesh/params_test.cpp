#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "remesh/equalize.h"
#include "remesh/params.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

Params valid() {
  Params p;
  p.e_min = 1.2;
  p.e_max = 1.8;
  return p;
}

bool names(const std::vector<FieldError>& errors, const std::string& field) {
  for (const auto& e : errors)
    if (e.field == field && !e.message.empty()) return true;
  return false;
}

}  // namespace

TEST_CASE("check() accepts the defaults with an interval", "[params]") { CHECK(check(valid()).empty()); }

TEST_CASE("check() names every invalid field", "[params]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Params p;
  SECTION("emin") {
    for (double bad : {0.0, -1.0, nan, inf}) {
      p = valid();
      p.e_min = bad;
      CHECK(names(check(p), "emin"));
    }
  }
  SECTION("emax") {
    for (double bad : {0.0, -1.0, nan, inf, 1.2, 1.0}) {
      p = valid();
      p.e_max = bad;
      CHECK(names(check(p), "emax"));
    }
  }
  SECTION("rings") {
    for (int bad : {0, 5, -1}) {
      p = valid();
      p.rings = bad;
      CHECK(names(check(p), "rings"));
    }
  }
  SECTION("iterations") {
    for (int bad : {0, -3, 1001}) {
      p = valid();
      p.iterations = bad;
      CHECK(names(check(p), "iterations"));
    }
    p = valid();
    p.max_iterations = 50;
    p.iterations = 51;
    CHECK(names(check(p), "iterations"));
  }
  SECTION("relax_every") {
    p = valid();
    p.relax_every = -1;
    CHECK(names(check(p), "relax_every"));
  }
  SECTION("flip_factor") {
    for (double bad : {-0.1, 1.1, nan, inf}) {
      p = valid();
      p.flip_factor = bad;
      CHECK(names(check(p), "flip_factor"));
    }
  }
  SECTION("threads") {
    p = valid();
    p.threads = 100000;
    CHECK(names(check(p), "threads"));
  }
  SECTION("several at once") {
    p = valid();
    p.e_min = -1;
    p.rings = 9;
    p.flip_factor = 2;
    const auto errors = check(p);
    CHECK(names(errors, "emin"));
    CHECK(names(errors, "rings"));
    CHECK(names(errors, "flip_factor"));
  }
}

TEST_CASE("equalize() throws ParamsError with the fields and LimitError on a tiny e_max", "[params]") {
  TriMesh mesh = test::make_icosphere(1, 1.0);
  Params p = valid();
  p.e_min = 2;  // > e_max
  p.e_max = 1;
  try {
    equalize(mesh, p);
    FAIL("no ParamsError");
  } catch (const ParamsError& e) {
    CHECK(names(e.errors(), "emax"));
  }
  p = valid();
  p.e_min = 1e-5;
  p.e_max = 2e-5;
  p.max_output_faces = 1'000'000;
  const std::size_t estimate = estimate_output_faces(mesh, p);
  CHECK(estimate > 1'000'000);
  try {
    equalize(mesh, p);
    FAIL("no LimitError");
  } catch (const LimitError& e) {
    const std::string message = e.what();
    CHECK(message.find(std::to_string(estimate)) != std::string::npos);
    CHECK(message.find("1000000") != std::string::npos);
  }
  CHECK(test::check_mesh_valid(mesh).empty());
}
