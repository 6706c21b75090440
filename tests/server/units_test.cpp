// Pieces of remeshd that need no process: options, static paths, SSE frames, storage.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <atomic>
#include <future>
#include <optional>
#include <thread>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <stop_token>
#include <string>

#include "io/mesh_io.h"
#include "job_manager.h"
#include "job_runner.h"
#include "job_store.h"
#include "log.h"
#include "metrics.h"
#include "open_file.h"
#include "options.h"
#include "routes.h"
#include "sse.h"
#include "static_files.h"
#include "upload_gate.h"
#include "support/mesh_generators.h"

using namespace remeshd;
namespace fs = std::filesystem;

namespace {

struct Args {
  std::vector<std::string> items;
  std::vector<char*> argv;
  explicit Args(std::vector<std::string> a) : items(std::move(a)) {
    items.insert(items.begin(), "remeshd");
    for (auto& s : items) argv.push_back(s.data());
  }
  ParseResult parse() { return parse_options(static_cast<int>(argv.size()), argv.data()); }
};

fs::path temp_dir() {
  std::random_device rd;
  fs::path p = fs::temp_directory_path() / ("remeshd-unit-" + std::to_string(rd()));
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST_CASE("options: defaults, command line, environment, errors", "[server][options]") {
  auto d = Args({}).parse();
  REQUIRE(d.options);
  CHECK(d.options->host == "127.0.0.1");
  CHECK(d.options->port == 8080);
  CHECK(d.options->max_upload_mb == 256);
  CHECK_FALSE(d.options->data_dir.empty());

  auto p = Args({"--port", "9000", "--workers=3", "--token", "t", "--log-format", "json", "--job-ttl-hours", "0.5"}).parse();
  REQUIRE(p.options);
  CHECK(p.options->port == 9000);
  CHECK(p.options->workers == 3);
  CHECK(p.options->token == "t");
  CHECK(p.options->log_format == "json");
  CHECK(p.options->job_ttl_hours == 0.5);

  setenv("REMESHD_QUEUE_SIZE", "7", 1);
  setenv("REMESHD_PORT", "9100", 1);
  auto e = Args({"--port", "9200"}).parse();
  unsetenv("REMESHD_QUEUE_SIZE");
  unsetenv("REMESHD_PORT");
  REQUIRE(e.options);
  CHECK(e.options->queue_size == 7);
  CHECK(e.options->port == 9200);  // the command line wins

  for (auto bad : std::vector<std::vector<std::string>>{{"--port", "70000"},
                                                         {"--port", "x"},
                                                         {"--workers"},
                                                         {"--log-format", "xml"},
                                                         {"--frobnicate", "1"},
                                                         {"stray"},
                                                         {"--max-iterations", "0"},
                                                         {"--heartbeat-seconds", "1e10"},
                                                         {"--heartbeat-seconds", "nan"},
                                                         {"--stream-lifetime-seconds", "1e12"},
                                                         // MiB counts whose bytes wrap round 2^64
                                                         {"--max-upload-mb", "17592186044416"},
                                                         {"--max-upload-mb", "0"},
                                                         // a queue that takes no job (every POST was a 503)
                                                         {"--queue-size", "0"},
                                                         {"--data-cap-mb", "17592186044416"},
                                                         // an empty token served without one
                                                         {"--token", ""},
                                                         {"--token="},
                                                         // streams all refused; threads past the system's
                                                         {"--max-streams", "0"},
                                                         {"--workers", "100000"},
                                                         {"--http-threads", "100000"}}) {
    CAPTURE(bad);
    auto r = Args(bad).parse();
    CHECK_FALSE(r.options);
    CHECK(r.exit_code == 2);
    CHECK(r.message.find('\n') == std::string::npos);
    CHECK(r.message.find(bad[0].substr(0, bad[0].find('='))) != std::string::npos);  // names the option
  }
  setenv("REMESHD_TOKEN", "", 1);
  auto empty_env = Args({}).parse();
  unsetenv("REMESHD_TOKEN");
  CHECK_FALSE(empty_env.options);
  CHECK(empty_env.message.find("REMESHD_TOKEN") != std::string::npos);
  auto h = Args({"--help"}).parse();
  CHECK_FALSE(h.options);
  CHECK(h.exit_code == 0);
  CHECK(h.message.find("--max-upload-mb") != std::string::npos);
  CHECK(h.message.find("REMESHD_DATA_DIR") != std::string::npos);
}

TEST_CASE("static_file never leaves the web root", "[server][static]") {
  fs::path root = temp_dir();
  fs::create_directories(root / "web" / "sub");
  std::ofstream(root / "web" / "index.html") << "x";
  std::ofstream(root / "web" / "sub" / "a.js") << "x";
  std::ofstream(root / "secret") << "x";
  fs::create_symlink(root / "secret", root / "web" / "link");
  fs::path web = root / "web";
  CHECK(static_file(web, "/") == fs::canonical(web / "index.html"));
  CHECK(static_file(web, "/sub/a.js") == fs::canonical(web / "sub" / "a.js"));
  CHECK(static_file(web, "/sub//a.js").has_value());
  for (const char* bad : {"/../secret", "/sub/../../secret", "/link", "/.hidden", "/sub/..", "relative",
                          "/nothing.js", "/sub/a.js\\..", "", "/sub/a.js/", "/index.html/"})
    CHECK_FALSE(static_file(web, bad));
  CHECK(mime_for("a.mjs").rfind("text/javascript", 0) == 0);
  CHECK(mime_for("a.WASM") == "application/wasm");
  CHECK(mime_for("a.map") == "application/json");
  CHECK(mime_for("a.unknown") == "application/octet-stream");
  fs::remove_all(root);
}

TEST_CASE("SSE frames and Last-Event-ID parsing", "[server][sse]") {
  remesh::IterationStats row;
  row.iteration = 7;
  std::string f = sse_iteration(row);
  CHECK(f.rfind("event: iteration\nid: 7\ndata: {", 0) == 0);
  CHECK(f.substr(f.size() - 2) == "\n\n");
  CHECK(sse_end(remesh::api::JobState::Failed) == "event: end\ndata: {\"state\":\"failed\"}\n\n");
  CHECK(parse_last_event_id("12") == 12);
  CHECK(parse_last_event_id(" 3 ") == 3);
  CHECK_FALSE(parse_last_event_id(""));
  CHECK_FALSE(parse_last_event_id("-1"));
  CHECK_FALSE(parse_last_event_id("4x"));
}

TEST_CASE("route patterns", "[server][routes]") {
  CHECK(route_pattern("/api/v1/jobs/{id}/events") == "/api/v1/jobs/([^/]+)/events");
  CHECK(route_pattern("/api/v1/openapi.yaml") == "/api/v1/openapi\\.yaml");
}

TEST_CASE("JobStore: a job removed while files are written for it stays removed", "[server][storage]") {
  // A download converting a result while its job is deleted: remove_all alone stopped part-way when
  // a file appeared in the directory, which stayed (with its state.json at times: the job came back
  // at the next start; QA, 9 of 25 deletes during conversions).
  fs::path root = temp_dir();
  std::vector<std::string> ids;
  {
    JobStore store(root);
    const std::string bytes(256 * 1024, 'x');
    for (int round = 0; round < 20; ++round) {
      remesh::api::JobRecord r;
      r.id = remesh::api::new_job_id();
      r.created_at = remesh::api::now_seconds();
      r.format = "obj";
      r.summary = nlohmann::json::object();
      store.create(r, "v 0 0 0\n");
      for (int i = 0; i < 40; ++i) store.write_file(r.id, "dual." + std::to_string(i) + ".ply", bytes);
      ids.push_back(r.id);
      std::atomic<bool> go{false};
      std::thread writer([&] {
        while (!go) std::this_thread::yield();
        for (int i = 0; i < 200; ++i) {  // until the directory is gone (or, were it to stay, 50 MB)
          try {
            store.write_file(r.id, "input." + std::to_string(i) + ".gltf", bytes);
          } catch (const std::exception&) {
            return;
          }
        }
      });
      go = true;
      std::this_thread::sleep_for(std::chrono::microseconds(200 * (round % 5)));
      store.remove(r.id);
      writer.join();
      CHECK_FALSE(fs::exists(store.file_path(r.id, "")));
    }
  }
  JobStore again(root);  // a restart
  std::vector<std::string> problems;
  CHECK(again.load_all(problems).empty());
  CHECK(problems.empty());
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(root / "jobs")) ++entries;
  CHECK(entries == 0);  // what late writers left went at the start
  fs::remove_all(root);
}

TEST_CASE("JobManager: a job submitted during shutdown is refused and stores nothing and one accepted before stays queued",
          "[server][restart]") {
  fs::path root = temp_dir();
  Logger log;
  Metrics metrics;
  auto job = [] {
    remesh::api::JobRecord r;
    r.id = remesh::api::new_job_id();
    r.created_at = remesh::api::now_seconds();
    r.format = "obj";
    r.summary = nlohmann::json::object();
    return r;
  };
  const remesh::api::JobRecord before = job(), during = job();
  {
    // Not started: no worker takes the accepted job, which stays queued.
    JobStore store(root);
    JobManager manager(ManagerConfig{}, store, log, metrics);
    CHECK(manager.submit(before, "v 0 0 0\n") == JobManager::Submit::Accepted);
    manager.shutdown();
    CHECK(manager.submit(during, "v 0 0 0\n") == JobManager::Submit::ShuttingDown);
    CHECK_FALSE(manager.record(during.id).has_value());
    CHECK_FALSE(fs::exists(store.file_path(during.id, "")));
    const auto kept = manager.record(before.id);
    REQUIRE(kept.has_value());
    CHECK(kept->state == remesh::api::JobState::Queued);
  }
  // What the next start finds on disk: the job accepted before, queued, and nothing of the other.
  std::vector<std::string> problems;
  const std::vector<JobStore::Loaded> stored = JobStore(root).load_all(problems);
  CHECK(problems.empty());
  REQUIRE(stored.size() == 1);
  CHECK(stored[0].record.id == before.id);
  CHECK(stored[0].record.state == remesh::api::JobState::Queued);
  fs::remove_all(root);
}

TEST_CASE("JobStore: atomic job directories, torn stats lines, bad ids", "[server][storage]") {
  fs::path root = temp_dir();
  {
    JobStore store(root);
    remesh::api::JobRecord r;
    r.id = remesh::api::new_job_id();
    r.created_at = remesh::api::now_seconds();
    r.params.e_min = 1;
    r.params.e_max = 2;
    r.format = "obj";
    r.summary = nlohmann::json::object();
    store.create(r, "v 0 0 0\n");
    CHECK(store.read_upload(r.id) == "v 0 0 0\n");
    remesh::IterationStats s;
    s.iteration = 1;
    store.append_stats(r.id, s);
    s.iteration = 2;
    store.append_stats(r.id, s);
    { std::ofstream(store.file_path(r.id, "stats.jsonl"), std::ios::app) << "{\"iteration\":3,\"ver"; }
    CHECK(store.load_stats(r.id).size() == 2);
    std::vector<std::string> problems;
    auto all = store.load_all(problems);
    REQUIRE(all.size() == 1);
    CHECK(all[0].record.id == r.id);
    CHECK(problems.empty());
    CHECK_THROWS(store.read_upload("../../etc/passwd"));
    // Leftovers of an interrupted creation are cleaned at start.
    fs::create_directories(root / "jobs" / ".tmp-abc");
    fs::create_directories(root / "jobs" / "not-a-job");
  }
  JobStore again(root);
  CHECK_THROWS_WITH(JobStore(root), Catch::Contains("in use by another remeshd"));  // one daemon per dir
  CHECK_FALSE(fs::exists(root / "jobs" / ".tmp-abc"));
  std::vector<std::string> problems;
  CHECK(again.load_all(problems).size() == 1);
  // A state.json cut short: skipped, said in words (it was the JSON library's text), files kept.
  const std::string damaged(32, 'a');
  fs::create_directories(root / "jobs" / damaged);
  std::ofstream(root / "jobs" / damaged / "state.json") << "{\"id\":\"aaaa";
  problems.clear();
  CHECK(again.load_all(problems).size() == 1);
  REQUIRE(problems.size() == 1);
  CHECK_THAT(problems[0], Catch::StartsWith(damaged) && Catch::Contains("does not parse as JSON") &&
                              !Catch::Contains("json.exception"));
  CHECK(fs::exists(root / "jobs" / damaged / "state.json"));
  // A missing upload is named without the path on the server (it reaches a job's error).
  CHECK_THROWS_WITH(again.read_upload(damaged), Catch::Contains("stored upload cannot be read") &&
                                                    !Catch::Contains(root.string()));
  fs::remove_all(root);
}

TEST_CASE("run_job hands each result file to the sink once, and none when cancelled", "[server][runner]") {
  // A small sphere, written as an OFF upload, remeshed to an interval around its edge length.
  const remesh::TriMesh sphere = remesh::test::make_icosphere(2, 10.0);
  double total = 0;
  for (auto e : sphere.edges()) total += sphere.calc_edge_length(e);
  const double mean = total / static_cast<double>(sphere.n_edges());
  remesh::api::JobRecord job;
  job.id = "0123456789abcdef0123456789abcdef";
  job.format = "off";
  job.params.e_min = 0.8 * mean;
  job.params.e_max = 1.2 * mean;
  job.params.iterations = 5;
  const std::string upload = remesh::write_mesh(sphere, remesh::Format::Off);

  std::map<std::string, std::string> files;
  auto sink = [&](const std::string& name, std::string_view bytes) {
    CHECK(files.count(name) == 0);
    files[name] = std::string(bytes);
  };
  const RunOutput out = run_job(job, upload, 1, {}, std::stop_token{}, sink);
  CHECK(out.result.outcome != remesh::Outcome::Cancelled);
  // Every format but those made on their first download (text glTF, from the OBJ).
  std::set<std::string> expected;
  for (const auto& f : remesh::api::remeshed_formats())
    if (!remesh::api::made_on_request(f)) expected.insert("remeshed." + f);
  for (const auto& f : remesh::api::dual_formats())
    if (!remesh::api::made_on_request(f)) expected.insert("dual." + f);
  CHECK(expected.size() + 2 == remesh::api::remeshed_formats().size() + remesh::api::dual_formats().size());
  std::set<std::string> got;
  for (const auto& [name, bytes] : files) {
    got.insert(name);
    CHECK(!bytes.empty());
  }
  CHECK(got == expected);
  // The files are the results: the remeshed OFF reads back as a closed mesh like the sphere.
  const remesh::LoadedMesh back = remesh::read_mesh(files.at("remeshed.off"), {remesh::Format::Off});
  CHECK(back.mesh.n_faces() > 0);
  CHECK(static_cast<long>(back.mesh.n_vertices()) - static_cast<long>(back.mesh.n_edges()) +
            static_cast<long>(back.mesh.n_faces()) == 2);

  // The same sphere placed 1e39 from the origin: STL, GLB and glTF (float32) cannot hold it and are not
  // written; the job's other files are (the run failed while writing them).
  {
    // 1e25 across (near 1e39 doubles lie about 1e23 apart: the sphere of radius 10 would be flat).
    remesh::TriMesh far = remesh::test::make_icosphere(2, 1e25);
    for (auto v : far.vertices()) far.point(v) += remesh::Vec3(1e39, 0, 0);
    remesh::api::JobRecord far_job = job;
    far_job.params.e_min *= 1e24;
    far_job.params.e_max *= 1e24;
    std::set<std::string> written;
    const RunOutput far_out = run_job(far_job, remesh::write_mesh(far, remesh::Format::Off), 1, {}, std::stop_token{},
                                      [&](const std::string& name, std::string_view) { written.insert(name); });
    CHECK(far_out.result.outcome != remesh::Outcome::Cancelled);
    // Named unwritable, text glTF with GLB (made on request, it stores float32 too).
    CHECK(std::set<std::string>(far_out.unwritable.begin(), far_out.unwritable.end()) ==
          std::set<std::string>{"remeshed.stl", "remeshed.glb", "remeshed.gltf", "dual.glb", "dual.gltf"});
    std::set<std::string> without_float32;
    for (const std::string& name : expected)
      if (!name.ends_with(".stl") && !name.ends_with(".glb")) without_float32.insert(name);
    CHECK(written == without_float32);
  }

  std::stop_source stopped;
  stopped.request_stop();
  std::size_t calls = 0;
  const RunOutput cancelled = run_job(job, upload, 1, {}, stopped.get_token(),
                                      [&](const std::string&, std::string_view) { ++calls; });
  CHECK(cancelled.result.outcome == remesh::Outcome::Cancelled);
  CHECK(calls == 0);
}

TEST_CASE("UploadGate: slots, a bounded wait, a bounded line, and close", "[server][uploads]") {
  using Clock = std::chrono::steady_clock;
  UploadGate gate(1, 0.3, 1);
  UploadGate::Entry first = gate.enter();
  REQUIRE(first.pass);
  CHECK(gate.busy() == 1);
  // The one slot taken: the next waits the whole wait, then is refused as busy.
  const auto start = Clock::now();
  UploadGate::Entry late = gate.enter();
  CHECK_FALSE(late.pass);
  CHECK(late.refusal == UploadGate::Refusal::Busy);
  CHECK(std::chrono::duration<double>(Clock::now() - start).count() >= 0.25);
  // One waiting already (the line holds one): another is refused at once.
  auto waiter = std::async(std::launch::async, [&] { return gate.enter().pass.has_value(); });
  while (gate.waiting() == 0) std::this_thread::yield();
  const auto at = Clock::now();
  CHECK_FALSE(gate.enter().pass);
  CHECK(std::chrono::duration<double>(Clock::now() - at).count() < 0.2);
  // The slot freed: the waiter gets it.
  first.pass.reset();
  CHECK(waiter.get());
  CHECK(gate.busy() == 0);  // its pass was dropped with the task's entry
  // Closed: a waiter is woken, and every later entry refused, as closed.
  UploadGate::Entry held = gate.enter();
  REQUIRE(held.pass);
  auto woken = std::async(std::launch::async, [&] { return gate.enter().refusal; });
  while (gate.waiting() == 0) std::this_thread::yield();
  gate.close();
  CHECK(woken.get() == UploadGate::Refusal::Closed);
  CHECK(gate.enter().refusal == UploadGate::Refusal::Closed);
  // First come, first served: a slot freed while one waits is that waiter's, not a newcomer's.
  UploadGate fair(1, 5, 4);
  UploadGate::Entry holding = fair.enter();
  REQUIRE(holding.pass);
  std::atomic<int> order{0};
  int waiter_turn = -1, newcomer_turn = -1;
  auto first_in_line = std::async(std::launch::async, [&] {
    UploadGate::Entry e = fair.enter();
    waiter_turn = order++;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return e.pass.has_value();
  });
  while (fair.waiting() == 0) std::this_thread::yield();
  holding.pass.reset();
  UploadGate::Entry newcomer = fair.enter();  // the moment the slot frees
  newcomer_turn = order++;
  CHECK(first_in_line.get());
  CHECK(newcomer.pass);
  CHECK(waiter_turn == 0);
  CHECK(newcomer_turn == 1);
  // Moving a pass moves the slot: released once.
  UploadGate two(2, 0, 4);
  UploadGate::Entry a = two.enter();
  std::optional<UploadGate::Pass> moved = std::move(a.pass);
  a.pass.reset();
  CHECK(two.busy() == 1);
  moved.reset();
  CHECK(two.busy() == 0);
}

TEST_CASE("OpenFile: reads a file by offset, keeps it when it is removed, refuses what is no file", "[server][storage]") {
  const fs::path dir = fs::temp_directory_path() / ("remeshd_open_file_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "result.obj";
  std::string text;
  for (int i = 0; i < 20000; ++i) text += "v " + std::to_string(i) + " 0 0\n";
  std::ofstream(path, std::ios::binary) << text;
  auto file = OpenFile::open(path);
  REQUIRE(file);
  CHECK(file->size() == text.size());
  fs::remove(path);  // as a job's removal does
  std::string back(text.size(), '\0');
  for (std::size_t at = 0; at < text.size();) {  // in pieces, as a download reads it
    const long got = file->read(at, back.data() + at, std::min<std::size_t>(70000, text.size() - at));
    REQUIRE(got > 0);
    at += static_cast<std::size_t>(got);
  }
  CHECK(back == text);
  char byte;
  CHECK(file->read(text.size(), &byte, 1) == 0);
  CHECK_FALSE(OpenFile::open(path));  // gone
  CHECK_FALSE(OpenFile::open(dir));   // a directory
  fs::remove_all(dir);
}
