// The job model: states, ids, and the job document's shape and round trip.
#include <catch2/catch.hpp>

#include <set>

#include "api/job.h"
#include "api/problem.h"

using nlohmann::json;
using namespace remesh;
using namespace remesh::api;

TEST_CASE("job ids are 32 hex characters and distinct", "[api][job]") {
  std::set<std::string> ids;
  for (int i = 0; i < 200; ++i) {
    std::string id = new_job_id();
    CHECK(is_valid_job_id(id));
    ids.insert(id);
  }
  CHECK(ids.size() == 200);
  for (const char* bad : {"", "abc", "../../etc/passwd", "0123456789abcdef0123456789abcdeF",
                          "0123456789abcdef0123456789abcde", "0123456789abcdef0123456789abcdef0",
                          "0123456789abcdef/123456789abcdef"})
    CHECK_FALSE(is_valid_job_id(bad));
}

TEST_CASE("state names round trip, final states", "[api][job]") {
  for (JobState s : {JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed,
                     JobState::Cancelling, JobState::Cancelled})
    CHECK(parse_state(state_name(s)) == s);
  CHECK_FALSE(parse_state("done"));
  CHECK(is_final(JobState::Succeeded));
  CHECK(is_final(JobState::Cancelled));
  CHECK_FALSE(is_final(JobState::Cancelling));
}

TEST_CASE("job document: fields, links only when succeeded, round trip", "[api][job]") {
  JobRecord r;
  r.id = new_job_id();
  r.created_at = 1'700'000'000.25;
  r.params.e_min = 0.5;
  r.params.e_max = 1.0;
  r.params.iterations = 10;
  r.filename = "bunny.obj";
  r.format = "obj";
  r.bytes = 1234;
  r.summary = json{{"vertices", 3}};
  json doc = job_to_json(r, "/api/v1", r.created_at + 2);
  CHECK(doc["id"] == r.id);
  CHECK(doc["state"] == "queued");
  CHECK(doc["created_at"] == "2023-11-14T22:13:20.250Z");
  CHECK(doc["started_at"].is_null());
  CHECK(doc["latest"].is_null());
  CHECK(doc["outcome"].is_null());
  CHECK(doc["thin_parts"].is_null());
  CHECK(doc["crossing_pairs"].is_null());
  CHECK(doc["layered"].is_null());  // known once the job has succeeded (false read "not layered")
  CHECK(doc["triangles"].is_null());
  CHECK(doc["seconds_by_step"].is_null());
  CHECK(doc["dual"].is_null());
  CHECK(doc["distance_to_input"].is_null());
  CHECK(doc["error"].is_null());
  CHECK(doc["params"]["emin"] == 0.5);
  CHECK(doc["params"]["weld"] == false);
  CHECK(doc["progress"]["iterations"] == 10);
  CHECK(doc["timings"]["queued_seconds"] == Approx(2.0));
  CHECK(doc["links"]["self"] == "/api/v1/jobs/" + r.id);
  CHECK(doc["links"]["input"] == "/api/v1/jobs/" + r.id + "/result?mesh=input&format=glb");
  CHECK_FALSE(doc["links"].contains("results"));

  r.state = JobState::Succeeded;
  r.started_at = r.created_at + 1;
  r.finished_at = r.created_at + 4;
  r.outcome = "converged";
  IterationStats last;
  last.iteration = 9;
  last.mean = 0.75;
  r.latest = last;
  r.iteration = 9;
  r.thin_parts = ThinParts{12, 7, 1.25};
  r.thin_parts->at_irregular = 5;
  r.thin_parts->at_creases = 4;
  r.thin_parts->vertex_limit = 3.5;
  r.thin_parts->vertices_thinner = 40, r.thin_parts->regular_thinner = 31;
  r.thin_parts->vertices_thicker = 900, r.thin_parts->regular_thicker = 811;
  r.thin_parts->sampled = true;
  r.crossing_pairs = 36;
  r.layered = true;
  r.triangles = TriangleQuality{1000, 31.5, 112.25, 0.0, 0.0125, 0.625, 0.9875};
  PhaseSeconds phases;
  phases.stellar = 0.5, phases.projection = 0.25, phases.untangle = 0.125;
  r.seconds_by_step = JobRecord::StepSeconds{phases, 1.0};
  DualStats dual;
  dual.atoms = 1200, dual.bonds = 1800;
  dual.rings = {{5, 12}, {6, 590}};
  dual.mean = 0.875, dual.deviation = 0.0625, dual.min = 0.5, dual.max = 1.25;
  dual.bond_min = 0.6875, dual.bond_max = 1.0625, dual.short_bonds = 36, dual.long_bonds = 108;
  r.dual = dual;
  r.distance_to_input = SurfaceDistance{0.25, 0.75, 50.0};
  doc = job_to_json(r, "/api/v1", r.created_at + 100);
  CHECK(doc["distance_to_input"] == json{{"hausdorff", 0.75}, {"relative", 0.015}, {"result_to_input", 0.25},
                                         {"input_to_result", 0.75}, {"diagonal", 50.0}});
  CHECK(doc["dual"]["atoms"] == 1200);
  CHECK(doc["dual"]["bonds"] == 1800);
  CHECK(doc["dual"]["rings"] == json{{"5", 12}, {"6", 590}});
  CHECK(doc["dual"]["bond_length"] == json{{"mean", 0.875}, {"deviation", 0.0625}, {"min", 0.5}, {"max", 1.25}});
  CHECK(doc["dual"]["bond_interval"] == json::array({0.6875, 1.0625}));
  CHECK(doc["dual"]["short_bonds"] == 36);
  CHECK(doc["dual"]["long_bonds"] == 108);
  CHECK(doc["dual"]["bonds_inside_fraction"] == Approx(1.0 - 144.0 / 1800.0));
  CHECK(doc["seconds_by_step"]["stellar"] == 0.5);
  CHECK(doc["seconds_by_step"]["projection"] == 0.25);
  CHECK(doc["seconds_by_step"]["untangle"] == 0.125);
  CHECK(doc["seconds_by_step"]["cleanup"] == 0.0);
  CHECK(doc["seconds_by_step"]["other"] == 0.125);  // 1 - (0.5 + 0.25 + 0.125)
  CHECK(doc["seconds_by_step"]["total"] == 1.0);
  CHECK(doc["thin_parts"]["outside"] == 12);
  CHECK(doc["thin_parts"]["in_thin_parts"] == 7);
  CHECK(doc["thin_parts"]["limit"] == 1.25);
  CHECK(doc["thin_parts"]["at_irregular_vertices"] == 5);
  CHECK(doc["thin_parts"]["at_kept_creases"] == 4);
  CHECK(doc["thin_parts"]["vertices"] ==
        json{{"limit", 3.5}, {"thinner", {{"vertices", 40}, {"regular", 31}}},
             {"thicker", {{"vertices", 900}, {"regular", 811}}}, {"sampled", true}});
  CHECK(doc["crossing_pairs"] == 36);
  CHECK(doc["layered"] == true);
  CHECK(doc["triangles"] == json{{"faces", 1000}, {"min_angle", 31.5}, {"max_angle", 112.25}, {"below_30", 0.0},
                                 {"above_90", 0.0125}, {"min_radius_ratio", 0.625}, {"mean_radius_ratio", 0.9875}});
  CHECK(doc["timings"]["queued_seconds"] == Approx(1.0));
  CHECK(doc["timings"]["run_seconds"] == Approx(3.0));
  REQUIRE(doc["links"].contains("results"));
  CHECK(doc["links"]["results"]["remeshed"].size() == 7);  // obj glb gltf ply off stl lammps
  CHECK(doc["links"]["results"]["dual"].size() == 7);      // obj glb gltf ply off xyz lammps
  CHECK(doc["links"]["results"]["dual"]["xyz"] == "/api/v1/jobs/" + r.id + "/result?mesh=dual&format=xyz");
  CHECK(doc["unwritable"] == json::array());
  {
    // Files the formats cannot hold are named, and their links left out (all were linked).
    JobRecord far = r;
    far.unwritable = {"remeshed.stl", "dual.glb"};
    const json far_doc = job_to_json(far, "/api/v1", r.created_at + 100);
    CHECK(far_doc["unwritable"] == json::array({"remeshed.stl", "dual.glb"}));
    CHECK(far_doc["links"]["results"]["remeshed"].size() == 6);
    CHECK_FALSE(far_doc["links"]["results"]["remeshed"].contains("stl"));
    CHECK(far_doc["links"]["results"]["remeshed"].contains("glb"));
    CHECK(far_doc["links"]["results"]["remeshed"].contains("gltf"));
    // Text glTF stores float32 as GLB does: without GLB, no glTF link either.
    CHECK(far_doc["links"]["results"]["dual"].size() == 5);
    CHECK_FALSE(far_doc["links"]["results"]["dual"].contains("glb"));
    CHECK_FALSE(far_doc["links"]["results"]["dual"].contains("gltf"));
    CHECK(job_from_json(far_doc).unwritable == far.unwritable);  // stored and read back
  }
  CHECK(doc["links"]["results"]["remeshed"]["lammps"] ==
        "/api/v1/jobs/" + r.id + "/result?mesh=remeshed&format=lammps");

  JobRecord back = job_from_json(doc);
  CHECK(back.id == r.id);
  CHECK(back.state == JobState::Succeeded);
  CHECK(back.created_at == Approx(r.created_at));
  CHECK(*back.finished_at == Approx(*r.finished_at));
  CHECK(back.params.e_max == 1.0);
  CHECK(back.latest->mean == 0.75);
  CHECK(back.outcome == std::optional<std::string>("converged"));
  REQUIRE(back.thin_parts);
  CHECK(back.thin_parts->outside == 12);
  CHECK(back.thin_parts->in_thin_parts == 7);
  CHECK(back.thin_parts->limit == 1.25);
  CHECK(back.thin_parts->at_irregular == 5);
  CHECK(back.thin_parts->at_creases == 4);
  CHECK(back.thin_parts->vertex_limit == 3.5);
  CHECK(back.thin_parts->vertices_thinner == 40);
  CHECK(back.thin_parts->regular_thinner == 31);
  CHECK(back.thin_parts->vertices_thicker == 900);
  CHECK(back.thin_parts->regular_thicker == 811);
  CHECK(back.thin_parts->sampled);
  CHECK(back.crossing_pairs == std::optional<std::size_t>(36));
  CHECK(back.layered);
  REQUIRE(back.triangles);
  CHECK(back.triangles->faces == 1000);
  CHECK(back.triangles->max_angle == 112.25);
  CHECK(back.triangles->above_90 == 0.0125);
  CHECK(back.triangles->mean_radius_ratio == 0.9875);
  {
    // A record written before the fields existed reads without them.
    json old = doc;
    old.erase("crossing_pairs");
    old.erase("layered");
    old.erase("triangles");
    CHECK_FALSE(job_from_json(old).crossing_pairs);
    CHECK_FALSE(job_from_json(old).layered);
    CHECK_FALSE(job_from_json(old).triangles);
  }
  {
    // A record written before the count existed reads with 0.
    json old = doc;
    old["thin_parts"].erase("at_irregular_vertices");
    old["thin_parts"].erase("at_kept_creases");
    old["thin_parts"].erase("vertices");
    const JobRecord before = job_from_json(old);
    REQUIRE(before.thin_parts);
    CHECK(before.thin_parts->in_thin_parts == 7);
    CHECK(before.thin_parts->at_irregular == 0);
    CHECK(before.thin_parts->at_creases == 0);
    CHECK(before.thin_parts->vertices_thinner == 0);
    CHECK(before.thin_parts->vertices_thicker == 0);
    CHECK_FALSE(before.thin_parts->sampled);
  }
  REQUIRE(back.distance_to_input);
  CHECK(back.distance_to_input->result_to_input == 0.25);
  CHECK(back.distance_to_input->input_to_result == 0.75);
  CHECK(back.distance_to_input->diagonal == 50.0);
  {
    // Documents written before the field existed read without it; one with a side JSON wrote as
    // null (infinity) reads without it too, the job kept.
    json old = doc;
    old.erase("distance_to_input");
    CHECK_FALSE(job_from_json(old).distance_to_input);
    json infinite = doc;
    infinite["distance_to_input"]["result_to_input"] = nullptr;
    JobRecord kept;
    REQUIRE_NOTHROW(kept = job_from_json(infinite));
    CHECK(kept.id == r.id);
    CHECK_FALSE(kept.distance_to_input);
  }
  REQUIRE(back.dual);
  CHECK(back.dual->atoms == 1200);
  CHECK(back.dual->bonds == 1800);
  CHECK(back.dual->rings == dual.rings);
  CHECK(back.dual->mean == 0.875);
  CHECK(back.dual->deviation == 0.0625);
  CHECK(back.dual->min == 0.5);
  CHECK(back.dual->max == 1.25);
  CHECK(back.dual->bond_min == 0.6875);
  CHECK(back.dual->bond_max == 1.0625);
  CHECK(back.dual->short_bonds == 36);
  CHECK(back.dual->long_bonds == 108);
  {
    // A ring size that is no number names the field.
    json bad = doc;
    bad["dual"]["rings"]["six"] = 3;
    CHECK_THROWS_WITH(job_from_json(bad), Catch::Contains("dual.rings"));
  }
  REQUIRE(back.seconds_by_step);
  CHECK(back.seconds_by_step->steps.stellar == 0.5);
  CHECK(back.seconds_by_step->steps.untangle == 0.125);
  CHECK(back.seconds_by_step->steps.sum() == 0.875);
  CHECK(back.seconds_by_step->total == 1.0);
  // A document written before the fields existed still reads.
  json old = doc;
  old.erase("thin_parts");
  old.erase("seconds_by_step");
  old.erase("dual");
  CHECK_FALSE(job_from_json(old).thin_parts);
  CHECK_FALSE(job_from_json(old).seconds_by_step);
  CHECK_FALSE(job_from_json(old).dual);

  json broken = doc;
  broken["state"] = "sleeping";
  CHECK_THROWS_AS(job_from_json(broken), std::runtime_error);
  broken = doc;
  broken["id"] = "../x";
  CHECK_THROWS_AS(job_from_json(broken), std::runtime_error);
}

TEST_CASE("problems carry status, title, detail and field errors", "[api][problem]") {
  Problem p = make_problem(422, "bad", {{"emin", "is required"}});
  CHECK(p.status == 422);
  CHECK(p.body["title"] == "Unprocessable Content");
  CHECK(p.body["errors"][0]["field"] == "emin");
  CHECK(problem_from_exception(MeshError("line 3: bad face")).status == 422);
  CHECK(problem_from_exception(MeshError("line 3: bad face")).body["detail"] == "line 3: bad face");
  CHECK(problem_from_exception(LimitError("too many")).status == 413);
  CHECK(problem_from_exception(ParamsError(std::vector<FieldError>{{"rings", "1..4"}})).body["errors"].size() == 1);
  CHECK(problem_from_exception(std::logic_error("x")).status == 500);
}
