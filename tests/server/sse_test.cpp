// Server-sent events: full history, Last-Event-ID, after the end, stream cap and lifetime, and many
// streams at once on 2 workers while /healthz keeps answering.
#include <catch2/catch.hpp>

#include <atomic>
#include <thread>

#include "daemon.h"

using nlohmann::json;
using namespace remesh::test;

namespace {

std::vector<SseEvent> of_kind(const SseStream& s, const std::string& kind) {
  std::vector<SseEvent> out;
  for (const auto& e : s.events)
    if (e.event == kind) out.push_back(e);
  return out;
}

}  // namespace

TEST_CASE("remeshd SSE: history, Last-Event-ID, after the end", "[server][sse]") {
  TempDir tmp;
  Daemon d(tmp.path / "data", {"--workers", "1", "--heartbeat-seconds", "0.2"});
  auto c = d.client();
  const std::string id = submit(c, sphere_obj(3), "emin=0.08&emax=0.12&iterations=6&run_all_iterations=true");
  const std::string path = "/api/v1/jobs/" + id + "/events";

  // Live: connects while queued or running, reads to the end.
  SseStream live = read_events(d.port(), path);
  CHECK(live.status == 200);
  REQUIRE(live.completed);
  auto states = of_kind(live, "state");
  auto rows = of_kind(live, "iteration");
  auto ends = of_kind(live, "end");
  REQUIRE(ends.size() == 1);
  CHECK(live.events.back().event == "end");
  CHECK(json::parse(ends[0].data)["state"] == "succeeded");
  REQUIRE(states.size() >= 3);
  CHECK(json::parse(states.front().data)["state"] == "queued");
  CHECK(json::parse(states.back().data)["state"] == "succeeded");
  REQUIRE(rows.size() == 6);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    CHECK(rows[i].id == std::to_string(i + 1));
    json row = json::parse(rows[i].data);
    CHECK(row["iteration"] == i + 1);
    CHECK(row.contains("mean"));
    CHECK(row.contains("regular_percent"));
  }
  CHECK_FALSE(live.retries.empty());

  // After the end: the whole history again, then the end.
  SseStream after = read_events(d.port(), path);
  CHECK(of_kind(after, "iteration").size() == 6);
  CHECK(after.events.back().event == "end");

  // Last-Event-ID: only the rows after it; the header or the query parameter.
  SseStream resumed = read_events(d.port(), path, {{"Last-Event-ID", "4"}});
  auto resumed_rows = of_kind(resumed, "iteration");
  REQUIRE(resumed_rows.size() == 2);
  CHECK(resumed_rows[0].id == "5");
  CHECK(resumed_rows[1].id == "6");
  CHECK(resumed.events.back().event == "end");
  CHECK(json::parse(resumed.events.front().data)["state"] == "running");
  SseStream by_query = read_events(d.port(), path + "?lastEventId=5");
  REQUIRE(of_kind(by_query, "iteration").size() == 1);
  CHECK(of_kind(by_query, "iteration")[0].id == "6");
  SseStream all_seen = read_events(d.port(), path, {{"Last-Event-ID", "6"}});
  CHECK(of_kind(all_seen, "iteration").empty());
  CHECK(all_seen.events.back().event == "end");
}

TEST_CASE("remeshd SSE: stream cap, lifetime with retry, heartbeats", "[server][sse]") {
  TempDir tmp;
  Daemon d(tmp.path / "data", {"--workers", "1", "--max-streams", "2", "--stream-lifetime-seconds", "1",
                               "--heartbeat-seconds", "0.2"});
  auto c = d.client();
  // A job that waits in the queue behind a long one: its streams only see pings.
  const std::string slow = submit(c, sphere_obj(4), "emin=0.02&emax=0.035&iterations=400&run_all_iterations=true");
  const std::string waiting = submit(c, sphere_obj(2), "emin=0.2&emax=0.35&iterations=2");
  const std::string path = "/api/v1/jobs/" + waiting + "/events";

  std::atomic<int> done{0};
  SseStream a, b;
  std::thread ta([&] { a = read_events(d.port(), path); ++done; });
  std::thread tb([&] { b = read_events(d.port(), path); ++done; });
  // Wait until both streams are open, then a third is refused.
  for (int i = 0; i < 200; ++i) {
    auto h = c.Get("/healthz");
    if (h && json::parse(h->body)["event_streams"] == 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  auto third = c.Get(path.c_str());
  REQUIRE(third);
  CHECK(third->status == 503);
  CHECK_FALSE(third->get_header_value("Retry-After").empty());
  auto metrics = c.Get("/metrics");
  REQUIRE(metrics);
  CHECK(metrics->body.find("\nremeshd_busy_refusals_total{reason=\"event_streams\"} 1\n") != std::string::npos);
  ta.join();
  tb.join();
  // Each stream ended after its lifetime with a retry hint, pings in between.
  for (const SseStream* s : {&a, &b}) {
    CHECK(s->status == 200);
    CHECK(s->completed);
    CHECK(s->retries.size() >= 2);  // the opening hint and the closing one
    bool pinged = false;
    for (const auto& comment : s->comments) pinged = pinged || comment.find("ping") != std::string::npos;
    CHECK(pinged);
    CHECK(of_kind(*s, "end").empty());
  }
  CHECK(c.Delete(("/api/v1/jobs/" + slow).c_str())->status == 202);
  CHECK(c.Delete(("/api/v1/jobs/" + waiting).c_str())->status == 202);
}

TEST_CASE("remeshd: many streams on 2 workers, /healthz keeps answering", "[server][sse][concurrency]") {
  TempDir tmp;
  Daemon d(tmp.path / "data", {"--workers", "2", "--heartbeat-seconds", "0.5"});
  auto c = d.client();
  std::vector<std::string> ids;
  for (int i = 0; i < 4; ++i)
    ids.push_back(submit(c, sphere_obj(3), "emin=0.07&emax=0.11&iterations=8&run_all_iterations=true"));

  constexpr int kClients = 16;  // twice httplib's default pool of 8
  std::vector<SseStream> streams(kClients);
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i)
    threads.emplace_back([&, i] { streams[i] = read_events(d.port(), "/api/v1/jobs/" + ids[i % ids.size()] + "/events"); });

  int health_ok = 0, health_fail = 0;
  std::size_t max_busy = 0;
  for (int i = 0; i < 40; ++i) {
    httplib::Client h("127.0.0.1", d.port());
    h.set_read_timeout(5);
    auto r = h.Get("/healthz");
    if (r && r->status == 200) {
      ++health_ok;
      max_busy = std::max<std::size_t>(max_busy, json::parse(r->body)["busy_workers"].get<std::size_t>());
    } else {
      ++health_fail;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  for (auto& t : threads) t.join();
  CHECK(health_fail == 0);
  CHECK(health_ok == 40);
  CHECK(max_busy <= 2);
  for (const SseStream& s : streams) {
    CHECK(s.status == 200);
    REQUIRE_FALSE(s.events.empty());
    CHECK(s.events.back().event == "end");
    CHECK(of_kind(s, "iteration").size() == 8);
  }
  for (const std::string& id : ids) CHECK(get_job(c, id)["state"] == "succeeded");
}

TEST_CASE("remeshd SSE: a client that leaves frees its stream slot before the next heartbeat", "[server][sse]") {
  // Heartbeats a minute apart: the slot of a client that hung up was held until the next one's
  // write failed, and with --max-streams 1 every other client got 503 meanwhile.
  TempDir tmp;
  Daemon d(tmp.path / "data", {"--workers", "1", "--max-streams", "1", "--heartbeat-seconds", "60"});
  auto c = d.client();
  const std::string slow = submit(c, sphere_obj(4), "emin=0.02&emax=0.035&iterations=400&run_all_iterations=true");
  const std::string waiting = submit(c, sphere_obj(2), "emin=0.2&emax=0.35&iterations=2");
  const std::string path = "/api/v1/jobs/" + waiting + "/events";
  auto open_streams = [&] { return json::parse(c.Get("/healthz")->body)["event_streams"].get<int>(); };
  {
    // Reads the first chunk (the retry hint and the queued state), then hangs up.
    httplib::Client leaving("127.0.0.1", d.port());
    bool got = false;
    auto r = leaving.Get(path.c_str(), [&](const char*, size_t) { return !(got = true); });
    CHECK(got);
  }
  int streams = -1;
  for (int i = 0; i < 100 && streams != 0; ++i) {
    streams = open_streams();
    if (streams != 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  CHECK(streams == 0);  // within 10 s, six times less than the heartbeat
  CHECK(c.Delete(("/api/v1/jobs/" + slow).c_str())->status == 202);
  CHECK(c.Delete(("/api/v1/jobs/" + waiting).c_str())->status == 202);
}
