// Uploads turned into jobs: format resolution, parameter and mesh errors, limits.
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include "api/upload.h"
#include "io/mesh_io.h"
#include "remesh/self_intersections.h"
#include "support/mesh_generators.h"

using namespace remesh;
using namespace remesh::api;
using remesh::test::make_icosphere;

namespace {

std::string sphere_obj() { return write_mesh(make_icosphere(2), Format::Obj); }

ParsedParams good_params() {
  return params_from_json(nlohmann::json{{"emin", 0.2}, {"emax", 0.4}, {"iterations", 3}});
}

std::set<std::string> fields_of(const std::vector<FieldError>& errors) {
  std::set<std::string> s;
  for (const auto& f : errors) s.insert(f.field);
  return s;
}

/// The field errors prepare_job refuses `bytes` (an OBJ) and `params` with; a failed check when it
/// takes them.
std::vector<FieldError> refusal(std::string_view bytes, const ParsedParams& params, const UploadLimits& limits = {}) {
  try {
    prepare_job(bytes, "x.obj", Format::Obj, params, limits);
  } catch (const ParamsError& e) {
    return e.errors();
  }
  FAIL("no ParamsError");
  return {};
}

}  // namespace

TEST_CASE("formats come from the parameter, the file name, then the Content-Type", "[api][upload]") {
  struct Row {
    const char* param;
    const char* filename;
    const char* content_type;
    std::optional<Format> expected;
    bool error;
  };
  const Row rows[] = {
      {"obj", "x.stl", "model/stl", Format::Obj, false},
      {"", "bunny.PLY", "model/obj", Format::Ply, false},
      {"", "mesh", "model/stl", Format::Stl, false},
      {"", "", "model/gltf-binary", Format::Glb, false},
      {"", "", "model/gltf+json; charset=utf-8", Format::Gltf, false},
      {"", "", "application/octet-stream", std::nullopt, false},
      {"", "", "", std::nullopt, false},
      {"", "a.unknown", "model/obj", Format::Obj, false},
      {"fbx", "a.obj", "", std::nullopt, true},
      {"xyz", "", "", std::nullopt, true},
      {"lammps", "", "", std::nullopt, true},  // written only
      {"", "atoms.lmp", "model/obj", Format::Obj, false},
  };
  for (const Row& r : rows) {
    INFO(r.param << " | " << r.filename << " | " << r.content_type);
    std::vector<FieldError> errors;
    CHECK(resolve_format(r.param, r.filename, r.content_type, errors) == r.expected);
    CHECK(errors.empty() == !r.error);
    if (r.error) CHECK(errors.front().field == "format");
  }
}

TEST_CASE("safe_stem keeps download names harmless", "[api][upload]") {
  CHECK(safe_stem("bunny.obj") == "bunny");
  CHECK(safe_stem("../../etc/passwd") == "passwd");
  CHECK(safe_stem("C:\\models\\cow.stl") == "cow");
  CHECK(safe_stem("a \"quoted\"; name.ply") == "a__quoted___name");
  CHECK(safe_stem("") == "mesh");
  CHECK(safe_stem(".hidden") == "hidden");
  CHECK(safe_stem(std::string(500, 'a') + ".obj").size() == 80);
}

TEST_CASE("prepare_job validates, reads and summarises", "[api][upload]") {
  std::string obj = sphere_obj();
  PreparedJob job = prepare_job(obj, "ball.obj", Format::Obj, good_params(), {});
  CHECK(is_valid_job_id(job.record.id));
  CHECK(job.record.state == JobState::Queued);
  CHECK(job.record.format == "obj");
  CHECK(job.record.bytes == obj.size());
  CHECK(job.record.summary["faces"] == job.mesh.mesh.n_faces());
  CHECK(job.record.summary["genus"] == nlohmann::json::array({0}));
  CHECK(job.record.params.iterations == 3);
  CHECK(job.record.summary["crossing_pairs"] == 0);
  CHECK(job.record.summary["layered"] == false);
  // Sniffed when no format is given.
  CHECK(prepare_job(obj, "", std::nullopt, good_params(), {}).record.format == "obj");
  // The faces that cross each other: two balls overlapping cross along a circle (as many pairs as
  // a recount finds); sixteen at one place touch everywhere but cross nowhere (their faces share
  // their corners' positions); 1 024 overlap too much to count (over 20 million pairs of spheres).
  const TriMesh two = test::stacked_copies(make_icosphere(2), 2, Vec3(1.2, 0.013, 0.007));  // the second moved
  const PreparedJob crossing = prepare_job(write_mesh(two, Format::Obj), "two.obj", Format::Obj, good_params(), {});
  CHECK(crossing.record.summary["crossing_pairs"] == find_self_intersections(crossing.mesh.mesh, 1).size());
  CHECK(crossing.record.summary["crossing_pairs"].get<std::size_t>() > 0);
  const PreparedJob stack = prepare_job(write_mesh(test::stacked_copies(make_icosphere(2), 16), Format::Obj),
                                        "stack.obj", Format::Obj, good_params(), {});
  CHECK(stack.record.summary["crossing_pairs"] == 0);
  CHECK(stack.record.summary["layered"] == false);
  const PreparedJob pile = prepare_job(write_mesh(test::stacked_copies(make_icosphere(1), 1024), Format::Obj),
                                       "pile.obj", Format::Obj, good_params(), {});
  CHECK(pile.record.summary["crossing_pairs"].is_null());
  CHECK(pile.record.summary["layered"] == true);
}

TEST_CASE("prepare_job: the errors it must give", "[api][upload]") {
  std::string obj = sphere_obj();
  auto params = [](nlohmann::json j) { return params_from_json(j); };

  SECTION("every bad parameter, before the mesh is read") {
    CHECK(fields_of(refusal("not a mesh", params({{"emin", -1}, {"emax", 0.4}, {"rings", 9}, {"iterations", "x"}}))) ==
          std::set<std::string>{"emin", "rings", "iterations"});
    CHECK_FALSE(refusal(obj, params({{"emin", 0.5}, {"emax", 0.4}})).empty());
  }
  SECTION("an emin no edge of the mesh can reach (its bounding-box diagonal is about 3.5)") {
    const std::vector<FieldError> errors = refusal(obj, params({{"emin", 5}, {"emax", 1e300}}));
    CHECK(fields_of(errors) == std::set<std::string>{"emin"});
    REQUIRE_FALSE(errors.empty());
    CHECK(errors.front().message.find("bounding-box diagonal") != std::string::npos);
    CHECK_NOTHROW(prepare_job(obj, "x.obj", Format::Obj, params({{"emin", 0.2}, {"emax", 1e300}}), {}));
  }
  SECTION("a bond_min whose edges no part of the mesh can hold, said in bonds") {
    // bond_min 2.5 asks for edges of 4.33, past the diagonal of about 3.5; the bound is 3.5 / sqrt(3).
    const std::vector<FieldError> errors = refusal(obj, params({{"bond_min", 2.5}, {"bond_max", 3}}));
    CHECK(fields_of(errors) == std::set<std::string>{"bond_min"});
    REQUIRE_FALSE(errors.empty());
    const std::string message = errors.front().message;
    CHECK_THAT(message, Catch::Contains("diagonal / sqrt(3)"));
    CHECK_THAT(message, !Catch::Contains("emin"));
    const PreparedJob ok = prepare_job(obj, "x.obj", Format::Obj, params({{"bond_min", 0.12}, {"bond_max", 0.2}}), {});
    CHECK(ok.record.params.e_min == Approx(0.12 * std::sqrt(3.0)));
    CHECK(ok.record.params.e_max == Approx(0.2 * std::sqrt(3.0)));
    UploadLimits out;
    out.max_output_faces = 100;
    CHECK_THROWS_WITH(prepare_job(obj, "x.obj", Format::Obj, params({{"bond_min", 0.001}, {"bond_max", 0.002}}), out),
                      Catch::Contains("raise bond_min/bond_max"));
  }
  SECTION("iterations over the service limit") {
    UploadLimits limits;
    limits.max_iterations = 2;
    CHECK(fields_of(refusal(obj, good_params(), limits)) == std::set<std::string>{"iterations"});
  }
  SECTION("unreadable meshes give the reader's message") {
    CHECK_THROWS_AS(prepare_job("v 0 0 0\nf 1 2 3\n", "x.obj", Format::Obj, good_params(), {}), MeshError);
    CHECK_THROWS_AS(prepare_job("", "x.obj", Format::Obj, good_params(), {}), MeshError);
    CHECK_THROWS_AS(prepare_job("\x01\x02garbage", "x", std::nullopt, good_params(), {}), MeshError);
    // Two triangles back to back (a tetrahedron with two coincident corners, once repaired).
    CHECK_THROWS_WITH(prepare_job("v 1 1 0.5\nv 0 0 0\nv 0 0 0\nv 1 0 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n", "x.obj",
                                  Format::Obj, good_params(), {}),
                      Catch::Contains("only 2 faces around it"));
  }
  SECTION("faces and estimated output faces over the limits") {
    UploadLimits limits;
    limits.max_faces = 10;
    CHECK_THROWS_AS(prepare_job(obj, "x.obj", Format::Obj, good_params(), limits), LimitError);
    UploadLimits out;
    out.max_output_faces = 100;
    CHECK_THROWS_AS(prepare_job(obj, "x.obj", Format::Obj, params({{"emin", 0.001}, {"emax", 0.002}}), out),
                    LimitError);
  }
}

TEST_CASE("utf8_prefix: filenames become valid UTF-8, cut between characters", "[api][upload]") {
  const std::string fffd = "\xEF\xBF\xBD";
  CHECK(utf8_prefix("bunny.obj", 200) == "bunny.obj");
  CHECK(utf8_prefix("\xFF.obj", 200) == fffd + ".obj");
  CHECK(utf8_prefix("caf\xC3\xA9.obj", 200) == "caf\xC3\xA9.obj");           // é kept
  CHECK(utf8_prefix("caf\xC3.obj", 200) == "caf" + fffd + ".obj");           // a lone lead byte
  CHECK(utf8_prefix("\xC0\xAF", 200) == fffd + fffd);                        // overlong '/'
  CHECK(utf8_prefix("\xED\xA0\x80", 200) == fffd + fffd + fffd);             // a surrogate
  CHECK(utf8_prefix("\xF0\x9F\x98\x80", 200) == "\xF0\x9F\x98\x80");         // an emoji, 4 bytes
  // "a" and 150 x é is 301 bytes: byte 200 falls inside an é, so the cut is at 199, before it.
  std::string long_name = "a";
  for (int i = 0; i < 150; ++i) long_name += "\xC3\xA9";
  const std::string cut = utf8_prefix(long_name, 200);
  CHECK(cut.size() == 199);
  CHECK(cut == long_name.substr(0, 199));
  CHECK(utf8_prefix("ab\xE2\x82\xAC", 4) == "ab");  // the euro sign (3 bytes) does not fit in 2
  // Whatever the bytes, the result is valid JSON text.
  std::string all;
  for (int b = 0; b < 256; ++b) all.push_back(static_cast<char>(b));
  CHECK_NOTHROW(nlohmann::json(utf8_prefix(all, 1000)).dump());
}

TEST_CASE("prepare_job keeps a filename that is not UTF-8 as valid UTF-8", "[api][upload]") {
  const PreparedJob job = prepare_job(sphere_obj(), "\xFF\xFEmesh.obj", Format::Obj, good_params(), {});
  CHECK(job.record.filename == "\xEF\xBF\xBD\xEF\xBF\xBDmesh.obj");
  CHECK_NOTHROW(job_to_json(job.record, "/api/v1", 0).dump());
  // Control characters too (the filename kept NUL, CR and LF).
  const PreparedJob controls =
      prepare_job(sphere_obj(), std::string("a\0b\r\nc\x7F.obj", 11), Format::Obj, good_params(), {});
  CHECK(controls.record.filename == "a\xEF\xBF\xBD" "b\xEF\xBF\xBD\xEF\xBF\xBD" "c\xEF\xBF\xBD.obj");
}
