#include "http_server.h"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cctype>
#include <cmath>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <regex>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "api/json_codec.h"
#include "api/problem.h"
#include "api/upload.h"
#include "body_decoder.h"
#include "connection_server.h"
#include "io/mesh_io.h"
#include "open_file.h"
#include "routes.h"
#include "sse.h"
#include "static_files.h"
#include "upload_gate.h"

namespace remeshd {

using nlohmann::json;
using remesh::FieldError;
using remesh::api::JobRecord;
using remesh::api::JobState;
using remesh::api::Problem;
using remesh::api::make_problem;

namespace {

/// The byte range the current request of this thread asks for (RFC 9110 14), taken out of
/// httplib's request by the pre-routing handler (as httplib parses it: -1 for a position not given;
/// kMalformed for a Range it could not parse): cpp-httplib 0.11 cut every answer to the ranges
/// asked for (an error's, an event stream's too), gave the range's end unclamped in Content-Range
/// ("bytes 242000-250000/242231" with 231 bytes), and a 416 without the length. Handlers that honour
/// ranges answer through send_ranged; every other answer is whole. Set for a GET (or HEAD) asking
/// for one range: several get the whole answer, a 200 (RFC 9110 14.2 lets a server ignore Range;
/// httplib built the multipart answer to all of them in memory: "bytes=0-,0-,..." made a 2 GB
/// answer of a 1 MB result).
thread_local std::optional<httplib::Range> t_range;
constexpr httplib::Range kMalformed{-1, -1};  ///< as httplib reads "bytes=-": never satisfiable

/// `bytes` as the answer, from a content provider: httplib 0.11.4 brotli-compresses every
/// set_content() body at its slowest setting when the client accepts br (browsers always do):
/// seconds for three.js or a big OBJ; a content provider is never compressed.
void provide(httplib::Response& res, std::string bytes, const std::string& mime) {
  auto data = std::make_shared<std::string>(std::move(bytes));
  const std::size_t size = data->size();
  res.set_content_provider(size, mime,
                           [data](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             if (offset >= data->size()) return false;  // never past the bytes
                             return sink.write(data->data() + offset, std::min(length, data->size() - offset));
                           });
}

constexpr const char* kPrefix = "/api/v1";
constexpr std::size_t kMiB = 1024 * 1024;
/// How many uploads' worth (--max-upload-mb each) of bytes decoded from coded bodies the requests
/// hold at once. A coded body costs its client far less than it decodes to (a gzip body of zeros:
/// 1.5 MB decodes to the 256 MiB limit), and each request holds its bytes until its mesh is read:
/// 80 such requests at once (the HTTP threads) held 20 GB. Past the budget, a coded upload gets a 503
/// (review). Plain bodies cost their clients what they hold.
constexpr std::size_t kCodedUploadsAtOnce = 4;
/// What a download reads from its file at a time.
constexpr std::size_t kPiece = 64 * 1024;
/// Uploads from this size on have the memory they took handed back to the system after their answer.
constexpr std::size_t kTrimAfterBytes = 8 * kMiB;
/// An upload of this size or more (its bytes as decoded) waits for a slot of the upload gate
/// (upload_gate.h) before its mesh is read; smaller ones, about 10 MB each to read, go at once.
constexpr std::size_t kGatedUploadBytes = 1 * kMiB;
constexpr std::size_t kMaxParamsBytes = 64 * 1024;
/// The query keys of POST /jobs that are not job parameters.
const std::vector<std::string> kUploadQueryKeys = {"format", "filename", "access_token"};
/// The most header bytes (names, values and their separators) a request may carry.
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

std::size_t header_bytes(const httplib::Request& req) {
  std::size_t bytes = 0;
  for (const auto& [name, value] : req.headers) bytes += name.size() + value.size() + 4;  // ": " and CRLF
  return bytes;
}
/// How much of an over-limit upload is read (and dropped) so the client can read the 413; beyond
/// it the connection is closed.
constexpr std::size_t kDrainBytes = 64 * kMiB;
/// How often an idle event stream checks that its client is still there.
constexpr double kLeftCheckSeconds = 1.0;

thread_local std::chrono::steady_clock::time_point t_request_start;
/// Did the pre-routing handler see this thread's current request? cpp-httplib 0.11 answers a request
/// line or header it cannot parse, a URI too long and a Range it cannot parse before routing: the
/// error handler is then the first to see the request. Cleared when the request is logged.
thread_local bool t_pre_routed = false;
/// Bytes an event stream wrote on this thread for the current request (the access log's `bytes`:
/// a chunked answer has no length of its own, and every stream was logged with bytes=0).
thread_local std::size_t t_streamed_bytes = 0;
/// The Content-Encoding of the current request's raw (not multipart) body, taken out of its
/// headers by the pre-routing handler so that httplib passes the coded bytes on: the upload
/// decodes them itself and checks that the stream ended (body_decoder.h). Empty: not coded.
thread_local std::string t_body_coding;

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string dump(const json& body) { return body.dump(-1, ' ', false, json::error_handler_t::replace); }

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(dump(body), "application/json");
}

void send_problem(httplib::Response& res, const Problem& p) {
  res.status = p.status;
  res.set_content(dump(p.body), "application/problem+json");
}

void send_problem(httplib::Response& res, int status, const std::string& detail,
                  const std::vector<FieldError>& errors = {}) {
  send_problem(res, make_problem(status, detail, errors));
}

std::string range_problem(const httplib::Request& req) {
  return "the Range header '" + req.get_header_value("Range") + "' is malformed or starts past the end of " +
         req.path;
}

/// A 416 for a range of an answer of `size` bytes: the problem, and the length (RFC 9110 15.5.17).
void send_unsatisfiable(const httplib::Request& req, httplib::Response& res, std::size_t size) {
  send_problem(res, 416, range_problem(req));
  res.set_header("Content-Range", "bytes */" + std::to_string(size));
}

/// The bytes of an answer of `size` bytes that go out: all of them with a 200, or the range the
/// request asks for (t_range): a 206 with Content-Range "bytes first-last/size", the last byte
/// clamped to the size. Nothing, with a 416 and "bytes */size" set, when the range starts past the
/// end, asks for the last 0 bytes or is malformed.
struct Span {
  std::size_t begin = 0, length = 0;
};
std::optional<Span> answer_span(const httplib::Request& req, httplib::Response& res, std::size_t size) {
  // If-Range (RFC 9110 13.1.5): the range only if the answer is still the one the client has (the
  // ETag it names, compared strongly); else the whole answer. It was ignored: a 206 of a changed file.
  if (t_range && req.has_header("If-Range") &&
      (!res.has_header("ETag") || req.get_header_value("If-Range") != res.get_header_value("ETag") ||
       req.get_header_value("If-Range").starts_with("W/")))
    t_range.reset();
  if (!t_range) {
    res.status = 200;
    return Span{0, size};
  }
  // httplib's parsed range: -1 for a position not given ("500-": to the end, "-500": the last 500).
  const auto [first, last] = *t_range;
  std::size_t begin = 0, end = 0;  // the bytes [begin, end]
  if (first >= 0 && static_cast<std::size_t>(first) < size) {
    begin = static_cast<std::size_t>(first);
    end = last < 0 ? size - 1 : std::min(static_cast<std::size_t>(last), size - 1);
  } else if (first < 0 && last > 0 && size > 0) {
    begin = size - std::min(static_cast<std::size_t>(last), size);
    end = size - 1;
  } else {
    send_unsatisfiable(req, res, size);
    return std::nullopt;
  }
  res.status = 206;
  res.set_header("Content-Range",
                 "bytes " + std::to_string(begin) + "-" + std::to_string(end) + "/" + std::to_string(size));
  return Span{begin, end - begin + 1};
}

/// `bytes` as the answer, whole or the range asked for (answer_span). A range goes out uncompressed
/// (Content-Range counts the bytes as they are); a whole answer as set_content() if `compress`,
/// else provided.
void send_ranged(const httplib::Request& req, httplib::Response& res, std::string bytes, const std::string& mime,
                 bool compress) {
  const auto span = answer_span(req, res, bytes.size());
  if (!span) return;
  if (res.status == 200 && compress) res.set_content(std::move(bytes), mime);
  else if (res.status == 200) provide(res, std::move(bytes), mime);
  else provide(res, bytes.substr(span->begin, span->length), mime);
}

/// An open file as the answer, whole or the range asked for (answer_span), read from the file as
/// the client takes it (open_file.h), 64 KiB at a time, never compressed (see provide).
void send_file(const httplib::Request& req, httplib::Response& res, std::shared_ptr<OpenFile> file,
               const std::string& mime) {
  const auto span = answer_span(req, res, file->size());
  if (!span) return;
  struct Reading {
    std::shared_ptr<OpenFile> file;
    Span span;
    std::unique_ptr<char[]> buffer = std::make_unique<char[]>(kPiece);
  };
  auto reading = std::make_shared<Reading>(Reading{std::move(file), *span});
  res.set_content_provider(span->length, mime,
                           [reading](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             const Span& s = reading->span;
                             if (offset >= s.length) return false;  // never past the bytes
                             const std::size_t n = std::min({length, s.length - offset, kPiece});
                             const long got = reading->file->read(s.begin + offset, reading->buffer.get(), n);
                             if (got <= 0) return false;  // the file shrank: the connection ends short
                             return sink.write(reading->buffer.get(), static_cast<std::size_t>(got));
                           });
}

/// A JSON document (a job, a list, statistics) as a 200, or the range asked for.
void send_document(const httplib::Request& req, httplib::Response& res, const json& body) {
  send_ranged(req, res, dump(body), "application/json", true);
}

/// Ends the connection once this answer is written. cpp-httplib 0.11 sends a handler's
/// "Connection: close" (beside its own "Keep-Alive") but keeps the connection and reads the next
/// request from it: a request sent after a refused body (Content-Length twice, or with
/// Transfer-Encoding: a smuggled request) was served. It ends a connection when writing an answer
/// fails, so the body goes out through a content provider that writes it whole and then reports
/// failure. For the post-routing handler: the headers, Content-Length included, are final by then,
/// and so is the body, cut to the range asked for (httplib would cut the provider's bytes again).
void close_after(const httplib::Request& req, httplib::Response& res) {
  const_cast<httplib::Request&>(req).ranges.clear();
  // httplib writes no body for HEAD, so the provider would never run and the connection would stay:
  // answered as a GET (the connection ends with it anyway; review: a HEAD with two Content-Lengths
  // got its 400 and the next request on the connection was served).
  if (req.method == "HEAD") const_cast<httplib::Request&>(req).method = "GET";
  res.headers.erase("Keep-Alive");
  auto body = std::make_shared<std::string>(std::move(res.body));
  res.body.clear();
  res.content_length_ = body->size();
  res.content_provider_ = [body](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    if (offset < body->size()) sink.write(body->data() + offset, std::min(length, body->size() - offset));
    return false;  // all written: the connection ends here
  };
}

/// The body's length as the access log gives it: a provided body (files, results, close_after) has
/// no bytes in res.body, only its Content-Length (the log said 0 for every download); a chunked
/// one (the event stream) has neither, and counts 0 here (the logger adds t_streamed_bytes).
std::size_t body_bytes(const httplib::Response& res) {
  return res.body.empty() && res.content_provider_ ? res.content_length_ : res.body.size();
}

/// Does the request carry a body? Without Content-Length and Transfer-Encoding it has none (RFC
/// 9112 6.3), and cpp-httplib 0.11's reader would wait for one until the client closed or the
/// read timed out (30 s).
bool has_body(const httplib::Request& req) {
  return req.has_header("Content-Length") || req.has_header("Transfer-Encoding");
}

/// The items of a list header (Transfer-Encoding, Content-Encoding) over all its lines, in order,
/// trimmed, lower case, empty ones dropped ("gzip, Chunked" -> gzip, chunked).
std::vector<std::string> header_list(const httplib::Request& req, const char* name) {
  std::string list;
  for (std::size_t i = 0; i < req.get_header_value_count(name); ++i) list.append(",").append(req.get_header_value(name, i));
  std::vector<std::string> codings;
  for (std::size_t begin = 0; begin < list.size();) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    std::string coding = list.substr(begin, end - begin);
    begin = end + 1;
    coding.erase(0, coding.find_first_not_of(" \t"));
    coding.erase(coding.find_last_not_of(" \t") + 1);
    for (char& c : coding) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (!coding.empty()) codings.push_back(std::move(coding));
  }
  return codings;
}

bool constant_time_equal(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

/// Keys of the query given more than once ("?emin=1&emin=2": which one did the client mean?).
std::vector<FieldError> repeated_query_keys(const httplib::Request& req) {
  std::vector<FieldError> errors;
  for (auto it = req.params.begin(); it != req.params.end(); it = req.params.upper_bound(it->first)) {
    const std::size_t n = req.params.count(it->first);
    if (n > 1) errors.push_back({it->first.substr(0, 64), "was given " + std::to_string(n) + " times; give it once"});
  }
  return errors;
}

/// The JSON text parsed (discarded when it does not parse), with the keys that an object of it
/// holds more than once in `repeated` ({"emin": 1, "emin": 2}: nlohmann keeps the last silently).
json parse_noting_repeats(const std::string& text, std::vector<std::string>& repeated) {
  std::vector<std::vector<std::string>> open;  // the keys of each object being read
  auto seen = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open.emplace_back();
    else if (event == json::parse_event_t::object_end && !open.empty()) open.pop_back();
    else if (event == json::parse_event_t::key && !open.empty()) {
      const std::string key = parsed.get<std::string>();
      std::vector<std::string>& keys = open.back();
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) {
        if (std::find(repeated.begin(), repeated.end(), key) == repeated.end()) repeated.push_back(key);
      } else {
        keys.push_back(key);
      }
    }
    return true;
  };
  json parsed = json::parse(text, seen, false);
  if (parsed.is_discarded()) repeated.clear();
  return parsed;
}

/// Why `text` is not JSON, as nlohmann's parser says it ("parse error at line 1, column 9: ...",
/// "number overflow parsing '1e400'"), without its exception's tag, at most 200 bytes.
std::string json_error(const std::string& text) {
  try {
    [[maybe_unused]] const json parsed = json::parse(text);
  } catch (const json::exception& e) {
    std::string message = e.what();
    if (const std::size_t tag = message.find("] "); message.starts_with("[json.exception") && tag != std::string::npos)
      message.erase(0, tag + 2);
    return message.substr(0, 200);
  }
  return "";
}

/// The query of a request target ("/path?a=1&b=x%3Dy"), each pair split at its first '=' and
/// percent-decoded ('+' as a space), in order, repeats kept. cpp-httplib 0.11 splits a pair at every
/// '=' and keeps the last piece as the value: "emin=0.1=0.12" was emin 0.12, a base64 token's
/// padding ("access_token=dG9rZW4=") was lost (401), "filename=my=file.obj" became "file.obj".
httplib::Params parse_query(const std::string& target) {
  httplib::Params params;
  const std::size_t question = target.find('?');
  if (question == std::string::npos) return params;
  const std::string_view query = std::string_view(target).substr(question + 1);
  for (std::size_t begin = 0; begin <= query.size();) {
    const std::size_t end = std::min(query.find('&', begin), query.size());
    const std::string_view pair = query.substr(begin, end - begin);
    begin = end + 1;
    const std::size_t eq = pair.find('=');
    const std::string_view key = pair.substr(0, eq);
    if (key.empty()) continue;  // "&&" or "=x": no name (cpp-httplib drops them too)
    const std::string_view value = eq == std::string_view::npos ? std::string_view() : pair.substr(eq + 1);
    params.emplace(httplib::detail::decode_url(std::string(key), true),
                   httplib::detail::decode_url(std::string(value), true));
  }
  return params;
}

/// Query parameters as a map (first value of each), minus the ones that are not job parameters.
std::map<std::string, std::string> query_params(const httplib::Request& req) {
  std::map<std::string, std::string> out;
  for (const auto& [k, v] : req.params) out.emplace(k, v);
  return out;
}

}  // namespace

struct HttpServer::Impl {
  Options options;
  JobManager& jobs;
  Metrics& metrics;
  Logger& log;
  std::filesystem::path web_root;
  ConnectionServer server;
  std::atomic<std::size_t> streams{0};
  /// Bytes decoded from coded uploads (Content-Encoding) that requests hold, all together: at most
  /// kCodedUploadsAtOnce uploads' worth (post_job).
  std::atomic<std::size_t> decoded_held{0};
  std::vector<std::pair<std::regex, std::string>> route_labels;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::mutex served_mutex;
  std::condition_variable served_changed;
  bool served = false;  ///< serve() has returned
  std::unique_ptr<UploadGate> upload_gate;  ///< made by setup()

  Impl(const Options& o, JobManager& j, Metrics& m, Logger& l, std::filesystem::path root)
      : options(o), jobs(j), metrics(m), log(l), web_root(std::move(root)) {}

  using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;

  /// Handlers never throw: anything escaping becomes a 500 problem.
  Handler guard(Handler h) {
    return [this, h = std::move(h)](const httplib::Request& req, httplib::Response& res) {
      try {
        h(req, res);
      } catch (const std::exception& e) {
        log.error("handler", {str("path", req.path), str("error", e.what())});
        send_problem(res, 500, std::string("internal error: ") + e.what());
      } catch (...) {
        send_problem(res, 500, "internal error");
      }
    };
  }

  /// Refuses a query parameter the route does not take, as the job parameters of a POST are (422,
  /// each named): a misspelt `?fromat=ply` got the default OBJ. `access_token` goes with every route.
  static Handler known_query(std::vector<std::string> known, Handler h) {
    std::string takes;
    for (const auto& k : known) takes += (takes.empty() ? "" : ", ") + k;
    const std::string message = "unknown parameter (this route takes " + (takes.empty() ? "none" : takes) + ")";
    return [known = std::move(known), message, h = std::move(h)](const httplib::Request& req,
                                                                  httplib::Response& res) {
      std::vector<FieldError> errors;
      for (const auto& [key, value] : req.params) {
        if (key == "access_token" || std::find(known.begin(), known.end(), key) != known.end()) continue;
        const std::string field = key.substr(0, 64);
        if (std::any_of(errors.begin(), errors.end(), [&](const FieldError& e) { return e.field == field; })) continue;
        errors.push_back({field, message});
      }
      if (!errors.empty()) return send_problem(res, 422, "invalid query: see errors", errors);
      h(req, res);
    };
  }

  std::string route_label(const httplib::Request& req) const {
    for (const auto& [re, label] : route_labels)
      if (std::regex_match(req.path, re)) return label;
    if (req.path.rfind("/api/", 0) == 0) return "unmatched";
    return "static";
  }

  /// The GET (also HEAD) and DELETE routes, as registered with httplib, for unparsed_range.
  std::vector<std::pair<std::regex, Handler>> get_routes, delete_routes;
  void get(const std::string& pattern, Handler h) {
    server.Get(pattern, h);
    get_routes.emplace_back(std::regex(pattern), std::move(h));
  }
  void del(const std::string& pattern, Handler h) {
    server.Delete(pattern, h);
    delete_routes.emplace_back(std::regex(pattern), std::move(h));
  }

  void setup();
  /// pre_route_checks, and a request it answers with its body unread ends its connection.
  httplib::Server::HandlerResponse pre_route(const httplib::Request& req, httplib::Response& res);
  httplib::Server::HandlerResponse pre_route_checks(const httplib::Request& req, httplib::Response& res);
  httplib::Server::HandlerResponse unparsed_range(const httplib::Request& req, httplib::Response& res);
  void cors_headers(httplib::Response& res) const;
  bool authorized(const httplib::Request& req) const;
  void post_job(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);
  void get_job(const httplib::Request& req, httplib::Response& res);
  void list_jobs(const httplib::Request& req, httplib::Response& res);
  void delete_job(const httplib::Request& req, httplib::Response& res);
  void events(const httplib::Request& req, httplib::Response& res);
  void result(const httplib::Request& req, httplib::Response& res);
  void stats(const httplib::Request& req, httplib::Response& res);
  void health(const httplib::Request& req, httplib::Response& res);
  void static_files(const httplib::Request& req, httplib::Response& res);
  /// The job named by the first path parameter, or a 404 answer.
  std::optional<JobRecord> find_job(const httplib::Request& req, httplib::Response& res);
  /// Has job `id` been removed, or is it being removed (its entry or its stored state gone)?
  bool removed(const std::string& id) const;
  json document(const JobRecord& r) const { return remesh::api::job_to_json(r, kPrefix, remesh::api::now_seconds()); }
};

void HttpServer::Impl::cors_headers(httplib::Response& res) const {
  if (options.cors_origin.empty()) return;
  res.set_header("Access-Control-Allow-Origin", options.cors_origin);
  if (options.cors_origin != "*") res.set_header("Vary", "Origin");
  res.set_header("Access-Control-Expose-Headers", "Location, ETag, Content-Disposition, Retry-After");
}

bool HttpServer::Impl::authorized(const httplib::Request& req) const {
  if (options.token.empty()) return true;
  std::string auth = req.get_header_value("Authorization");
  // The scheme is case-insensitive (RFC 9110 11.1): "bearer" and "BEARER" too.
  const bool bearer = auth.size() > 7 && auth[6] == ' ' &&
                      std::equal(auth.begin(), auth.begin() + 6, "bearer", [](char a, char b) {
                        return std::tolower(static_cast<unsigned char>(a)) == b;
                      });
  if (bearer && constant_time_equal(auth.substr(7), options.token)) return true;
  // EventSource and download links cannot set headers: the token may come as a query parameter.
  if (req.has_param("access_token") && constant_time_equal(req.get_param_value("access_token"), options.token))
    return true;
  return false;
}

void HttpServer::Impl::setup() {
  unsigned threads = options.http_threads ? options.http_threads : options.max_streams + 16;
  server.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  // At most half of the HTTP threads the event streams leave wait at the gate, so that the rest
  // still answer (the page's polls, downloads, health checks) with every stream open.
  const unsigned slots = options.upload_slots ? options.upload_slots : static_cast<unsigned>(jobs.gauges().workers);
  const unsigned spare = threads > options.max_streams ? threads - options.max_streams : 0;
  upload_gate = std::make_unique<UploadGate>(slots, options.upload_wait_seconds, std::max(1u, spare / 2));
  server.set_payload_max_length(options.max_upload_mb * kMiB + kMiB);  // Content-Length; chunked counted below
  // httplib's default also sets SO_REUSEPORT, which lets a second daemon bind the same port.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const void*>(&yes), sizeof(yes));
  });
  server.set_keep_alive_timeout(5);
  server.set_read_timeout(30);
  server.set_write_timeout(30);

  for (const RouteSpec& r : kRoutes)
    route_labels.emplace_back(std::regex(route_pattern(r.path)), r.path);

  server.set_pre_routing_handler(
      [this](const httplib::Request& req, httplib::Response& res) { return pre_route(req, res); });
  server.set_post_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    cors_headers(res);
    res.set_header("X-Content-Type-Options", "nosniff");
    // (A client that says "Connection: close" has its connection closed by httplib.)
    if (res.get_header_value("Connection") == "close" && req.get_header_value("Connection") != "close" &&
        !res.content_provider_)
      close_after(req, res);
  });
  server.set_error_handler(httplib::Server::HandlerWithResponse([this](const httplib::Request& req,
                                                                       httplib::Response& res) {
    if (!t_pre_routed && res.status == 416) return unparsed_range(req, res);
    // Answered before routing: timed from here (it was timed from this thread's previous request,
    // hours for an idle thread).
    if (!t_pre_routed) t_request_start = std::chrono::steady_clock::now();
    if (!res.body.empty() || res.content_length_ > 0) return httplib::Server::HandlerResponse::Unhandled;
    std::string detail;
    switch (res.status) {
      case 404: detail = "no such route: " + req.method + " " + req.path; break;
      case 413: detail = "the request body is too large"; break;
      case 400:
        // A request line cpp-httplib refused before routing: what of it, when it can be told (it
        // said the same for every cause).
        if (!req.method.empty() && !req.version.empty()) {  // a request line of three parts
          // The version first: HTTP/2's preface (PRI * HTTP/2.0) is a version not served.
          if (!t_pre_routed && req.version != "HTTP/1.1" && req.version != "HTTP/1.0") {
            res.status = 505;
            detail = "the HTTP version '" + req.version.substr(0, 40) + "' is not supported: send HTTP/1.1";
            break;
          }
          // TRACE and CONNECT parse, and reach no route.
          static const std::set<std::string> served = {"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS"};
          if (!served.count(req.method)) {
            std::string upper = req.method;
            for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
            res.status = 501;
            detail = "the method '" + req.method.substr(0, 40) +
                     "' is not implemented here (GET, HEAD, POST, DELETE, OPTIONS" +
                     (served.count(upper) ? "; methods are upper case" : "") + ")";
            break;
          }
        }
        if (!t_pre_routed && (req.method.empty() || req.version.empty())) {
          detail = "malformed request: the request line does not parse as 'METHOD target HTTP/1.1' (each line "
                   "of the request line and headers ends with CR LF)";
          break;
        }
        // cpp-httplib says no more than the status: name what makes a request unreadable.
        detail = "malformed request: a request line or header that does not parse as HTTP/1.1, a header line "
                 "longer than the server reads (8 KiB), or a body that does not match its Content-Length, "
                 "Transfer-Encoding or multipart boundary";
        if (req.get_header_value("Content-Type").find("multipart/form-data") != std::string::npos)
          detail += " (multipart/form-data: nothing may follow the boundary parameter, e.g. no '; charset=')";
        break;
      case 414: detail = "the request's URI is longer than the server reads (8 KiB): send parameters in the body"; break;
      case 416: detail = range_problem(req); break;
      default: detail = remesh::api::status_title(res.status);
    }
    send_problem(res, make_problem(res.status, detail));
    // The connection ends with these (the next bytes may not be a request): httplib kept it open
    // after a request it could not read, for 5 s, and read what followed as a request.
    if (!t_pre_routed || res.status == 501 || res.status == 505) close_after(req, res);
    return httplib::Server::HandlerResponse::Handled;
  }));
  server.set_exception_handler([this](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    try {
      if (ep) std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    log.error("handler", {str("path", req.path), str("error", what)});
    send_problem(res, 500, "internal error: " + what);
  });
  server.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    double secs = seconds_since(t_request_start);
    t_pre_routed = false;
    std::string route = route_label(req);
    metrics.observe_request(req.method, route, res.status, secs);
    log.info("request", {str("method", req.method), str("path", req.path), str("route", route),
                         num("status", res.status), num("ms", std::round(secs * 1e5) / 100),
                         num("bytes", static_cast<double>(body_bytes(res) + t_streamed_bytes)),
                         str("remote", req.remote_addr)});
    t_streamed_bytes = 0;  // a request refused before pre_route is logged next on this thread
  });

  const std::string jobs_path = std::string(kPrefix) + "/jobs";
  const std::string job_path = jobs_path + "/([^/]+)";
  get("/healthz", guard([this](const auto& req, auto& res) { health(req, res); }));
  get("/metrics", guard([this](const auto&, auto& res) {
        Gauges g = jobs.gauges();
        g.open_streams = streams.load();
        g.uploads_reading = upload_gate->busy();
        g.uploads_waiting = upload_gate->waiting();
        res.set_content(metrics.render(g), "text/plain; version=0.0.4; charset=utf-8");
      }));
  get(std::string(kPrefix) + "/openapi\\.yaml", guard([](const auto& req, auto& res) {
        send_ranged(req, res, openapi_yaml(), "application/yaml", true);
      }));
  server.Post(jobs_path, [this](const httplib::Request& req, httplib::Response& res,
                                const httplib::ContentReader& reader) {
    try {
      post_job(req, res, reader);
    } catch (const std::exception& e) {
      log.error("handler", {str("path", req.path), str("error", e.what())});
      send_problem(res, 500, std::string("internal error: ") + e.what());
    } catch (...) {
      send_problem(res, 500, "internal error");
    }
  });
  get(jobs_path, guard(known_query({"state", "limit", "offset"},
                                   [this](const auto& req, auto& res) { list_jobs(req, res); })));
  get(job_path, guard(known_query({}, [this](const auto& req, auto& res) { get_job(req, res); })));
  del(job_path, guard(known_query({}, [this](const auto& req, auto& res) { delete_job(req, res); })));
  get(job_path + "/events",
      guard(known_query({"lastEventId"}, [this](const auto& req, auto& res) { events(req, res); })));
  get(job_path + "/result",
      guard(known_query({"mesh", "format"}, [this](const auto& req, auto& res) { result(req, res); })));
  get(job_path + "/stats",
      guard(known_query({"format"}, [this](const auto& req, auto& res) { stats(req, res); })));
  get("/.*", guard([this](const auto& req, auto& res) { static_files(req, res); }));
  // Any other POST, PUT or PATCH: no such route. Routed with a content reader so that a request
  // without a body is answered at once (cpp-httplib 0.11 otherwise waits for a body that has no
  // length until its read timeout, 30 s); a body, if any, is read and dropped.
  auto no_route = [](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
    if (has_body(req))
      if (!reader([](const char*, std::size_t) { return true; })) res.set_header("Connection", "close");
    send_problem(res, 404, "no such route: " + req.method + " " + req.path);
  };
  server.Post("/.*", no_route);
  server.Put("/.*", no_route);
  server.Patch("/.*", no_route);
}

/// Checks every request before it is routed (and one cpp-httplib answered before routing, see
/// unparsed_range): framing, header size, auth, repeated query keys; takes the query and the byte
/// range out of httplib's hands.
httplib::Server::HandlerResponse HttpServer::Impl::pre_route(const httplib::Request& req,
                                                             httplib::Response& res) {
  const auto answer = pre_route_checks(req, res);
  // Answered before its body is read: the connection ends with the answer, or the body would be
  // read as the next request (connection_server.h keeps what was read past the head; review: a
  // 401 to a POST whose body was a request ran that request).
  if (answer == httplib::Server::HandlerResponse::Handled && has_body(req) && !res.has_header("Connection"))
    res.set_header("Connection", "close");
  return answer;
}

httplib::Server::HandlerResponse HttpServer::Impl::pre_route_checks(const httplib::Request& req,
                                                                    httplib::Response& res) {
  t_request_start = std::chrono::steady_clock::now();
  t_pre_routed = true;
  t_streamed_bytes = 0;
  t_body_coding.clear();
  // The query as sent, before anything reads a parameter (the token included), and the byte range
  // taken for the handler to apply (t_range), so that httplib applies none. The request object is
  // httplib's own, not const; only its parsed parameters and ranges change.
  auto& request = const_cast<httplib::Request&>(req);
  request.params = parse_query(req.target);
  t_range.reset();
  // One range of one Range header; any other is ignored (the whole answer; RFC 9110 14.2).
  if (req.ranges.size() == 1 && req.get_header_value_count("Range") == 1 && (req.method == "GET" || req.method == "HEAD"))
    t_range = req.ranges.front();
  request.ranges.clear();
  // Both framings: RFC 9112 6.3 has a server refuse the message and close the connection (a
  // proxy in front may have read it the other way: the shape of request smuggling).
  if (req.has_header("Content-Length") && req.has_header("Transfer-Encoding")) {
    res.set_header("Connection", "close");
    send_problem(res, 400, "malformed request: both Content-Length and Transfer-Encoding are set");
    return httplib::Server::HandlerResponse::Handled;
  }
  // cpp-httplib 0.11 reads a body as chunked only when Transfer-Encoding is exactly "chunked"; any
  // other value it read as a body without a length, to the end of the connection, and answered 400
  // after the 30 s read timeout. RFC 9112 6.3: chunked not last is a 400 (the length is unknown);
  // 6.1: a coding before it that the server does not apply (gzip, chunked) is a 501. Both close.
  if (req.has_header("Transfer-Encoding")) {
    const std::vector<std::string> codings = header_list(req, "Transfer-Encoding");
    // One field whose whole value is chunked (any case, blanks around it): httplib reads only
    // that as chunked, and read "chunked," (an empty item, dropped from `codings`) to the end.
    std::string only = req.get_header_value("Transfer-Encoding");
    only.erase(0, only.find_first_not_of(" \t"));
    only.erase(only.find_last_not_of(" \t") + 1);
    const bool plain_chunked = req.get_header_value_count("Transfer-Encoding") == 1 && codings.size() == 1 &&
                               codings.front() == "chunked" && only.size() == 7;
    if (!plain_chunked) {
      // chunked alone, but spelt otherwise ("chunked,", or given on two lines): a 400 as well; so
      // is chunked twice (RFC 9112 7: a body is chunked once), which was called a coding not
      // implemented.
      const bool all_chunked = std::all_of(codings.begin(), codings.end(), [](const auto& c) { return c == "chunked"; });
      const bool chunked_last = codings.size() > 1 && codings.back() == "chunked" && !all_chunked;
      res.set_header("Connection", "close");
      send_problem(res, chunked_last ? 501 : 400,
                   "Transfer-Encoding '" + req.get_header_value("Transfer-Encoding").substr(0, 60) + "': " +
                       (chunked_last ? "no coding but chunked is implemented"
                        : all_chunked && codings.size() > 1 ? "chunked is given more than once (a body is chunked once)"
                        : all_chunked ? "write it as the one value 'chunked'"
                                      : "the body's length is unknown (chunked must be the last coding)"));
      return httplib::Server::HandlerResponse::Handled;
    }
  }
  // Content-Length more than once with different values: the body's end is unknown (RFC 9110 8.6,
  // RFC 9112 6.3: 400, and close the connection). cpp-httplib 0.11 took the first and a proxy in
  // front may take the last. The same value repeated is one length (RFC 9110 8.6 allows it).
  for (std::size_t i = 1; i < req.get_header_value_count("Content-Length"); ++i) {
    const std::string first = req.get_header_value("Content-Length");
    const std::string other = req.get_header_value("Content-Length", i);
    if (other == first) continue;
    res.set_header("Connection", "close");
    send_problem(res, 400, "malformed request: Content-Length is given more than once with different values ('" +
                               first.substr(0, 20) + "', '" + other.substr(0, 20) + "')");
    return httplib::Server::HandlerResponse::Handled;
  }
  // A Content-Length that is not a number ("3, 10" on one line: httplib took 3) leaves the body's
  // end unknown, as two different ones do.
  if (req.has_header("Content-Length")) {
    const std::string length = req.get_header_value("Content-Length");
    if (length.empty() || length.find_first_not_of("0123456789") != std::string::npos) {
      res.set_header("Connection", "close");
      send_problem(res, 400, "malformed request: Content-Length '" + length.substr(0, 20) + "' is not a number");
      return httplib::Server::HandlerResponse::Handled;
    }
  }
  // A header that decides the answer, given twice: httplib took the first (Authorization right then
  // wrong was let in, a proxy in front may take the last). Refused, naming it.
  // (If-None-Match is a list: given twice, it is one list of both; the download joins them.)
  // (Range given twice is ignored, as any range not of one part: the whole answer.)
  for (const char* name : {"Authorization", "If-Range", "Last-Event-ID", "Content-Type"}) {
    if (const std::size_t n = req.get_header_value_count(name); n > 1) {
      send_problem(res, 400, std::string("malformed request: the header ") + name + " is given " + std::to_string(n) +
                                 " times; give it once");
      return httplib::Server::HandlerResponse::Handled;
    }
  }
  // A body coding cpp-httplib 0.11 does not decode (zstd, compress, a list) it passed on as it came:
  // the job was made of the coded bytes. It decodes gzip, deflate and br.
  // It matches the name exactly ("GZIP" was passed on too): the coding is named to it as it knows
  // it (RFC 9110 8.4.1: any case; x-gzip is gzip). Only for a body: a GET saying "UTF-8" there is
  // served as before.
  if (has_body(req) && req.has_header("Content-Encoding")) {
    std::vector<std::string> codings;
    for (std::string& coding : header_list(req, "Content-Encoding"))
      if (coding != "identity") codings.push_back(coding == "x-gzip" ? "gzip" : std::move(coding));
    const std::string list = req.get_header_value("Content-Encoding");
    const bool known = codings.size() == 1 && (codings[0] == "gzip" || codings[0] == "deflate" || codings[0] == "br");
    if (codings.size() > 1 || (codings.size() == 1 && !known)) {
      send_problem(res, 415, "Content-Encoding '" + list.substr(0, 40) +
                                 "' is not supported: send the body as it is, or coded once with one of gzip, "
                                 "deflate, br");
      return httplib::Server::HandlerResponse::Handled;
    }
    auto& headers = const_cast<httplib::Request&>(req).headers;
    headers.erase("Content-Encoding");
    if (known && !req.is_multipart_form_data()) t_body_coding = codings[0];
    else if (known) headers.emplace("Content-Encoding", codings[0]);  // decoded by httplib, before its parts
  }
  // cpp-httplib 0.11 reads no body for GET, HEAD and OPTIONS: the bytes of one would be read as the
  // next request on the connection (review: GET /healthz with a body that was 'GET /metrics' served
  // both). Refused, and the connection closed.
  if ((req.method == "GET" || req.method == "HEAD" || req.method == "OPTIONS") &&
      (req.has_header("Transfer-Encoding") ||
       (req.has_header("Content-Length") && req.get_header_value("Content-Length").find_first_not_of('0') != std::string::npos))) {
    res.set_header("Connection", "close");
    send_problem(res, 400, "malformed request: a " + req.method + " request carries no body here");
    return httplib::Server::HandlerResponse::Handled;
  }
  // cpp-httplib 0.11 limits each header line (8 KiB) but not their number; the whole block has
  // been read by now, so this bounds what the request costs from here on, and says why.
  if (const std::size_t bytes = header_bytes(req); bytes > kMaxHeaderBytes) {
    res.set_header("Connection", "close");
    send_problem(res, 431, "the request's headers take " + std::to_string(bytes) + " bytes; at most " +
                               std::to_string(kMaxHeaderBytes) + " are accepted");
    jobs.trim_memory_soon();
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.method == "OPTIONS" && !options.cors_origin.empty()) {
    res.status = 204;
    res.set_header("Access-Control-Allow-Methods", "GET, POST, DELETE, OPTIONS");
    res.set_header("Access-Control-Allow-Headers", "Authorization, Content-Type, Last-Event-ID");
    res.set_header("Access-Control-Max-Age", "600");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.path.rfind("/api/", 0) == 0 && !authorized(req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"remeshd\"");
    send_problem(res, 401, "this server requires 'Authorization: Bearer <token>'");
    return httplib::Server::HandlerResponse::Handled;
  }
  if (req.path.rfind("/api/", 0) == 0) {
    if (auto errors = repeated_query_keys(req); !errors.empty()) {
      send_problem(res, 422, "invalid query: see errors", errors);
      return httplib::Server::HandlerResponse::Handled;
    }
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

namespace {

/// One byte range "first-last", "first-" or "-suffix" (RFC 9110 14.1.2) whose numbers run past 64
/// bits, which httplib's parser refuses: a number past 2^62 is taken as 2^62, longer than any
/// answer, so the range is clamped to the answer's end as any other (QA: "bytes=0-99999999999999999999"
/// was a 416, and so was "bytes=-99999999999999999999", the whole answer). nullopt for anything else.
std::optional<httplib::Range> long_byte_range(std::string_view spec) {
  constexpr long long kHuge = 1LL << 62;
  const std::size_t dash = spec.find('-');
  if (dash == std::string_view::npos) return std::nullopt;
  const std::string_view first = spec.substr(0, dash), last = spec.substr(dash + 1);
  auto digits = [](std::string_view d) { return !d.empty() && d.find_first_not_of("0123456789") == std::string_view::npos; };
  auto number = [&](std::string_view d) {
    long long v = 0;
    for (char ch : d) v = v > kHuge / 10 ? kHuge : std::min(kHuge, v * 10 + (ch - '0'));
    return v;
  };
  if (first.empty()) return digits(last) ? std::optional(httplib::Range{-1, number(last)}) : std::nullopt;
  if (!digits(first) || !(last.empty() || digits(last))) return std::nullopt;
  const long long a = number(first), b = last.empty() ? -1 : number(last);
  if (b >= 0 && b < a) return std::nullopt;
  return httplib::Range{a, b};
}

}  // namespace

/// A Range header cpp-httplib 0.11 cannot parse ("items=0-5", "bytes=zz", "bytes=5-1", "Bytes=0-5")
/// it answers with a bare 416 before routing (Server::process_request): neither the pre-routing
/// handler nor a route sees the request, the error handler is the first to. Routed here as httplib
/// would have: a unit other than bytes is ignored (RFC 9110 14.2: the whole answer), the unit's case
/// does not matter ("Bytes=0-5" is bytes 0-5), and a malformed bytes range is kMalformed: a 416 that
/// gives the length ("bytes */N") from the handlers that honour ranges, the whole answer from the
/// others (the event stream). GET, HEAD and DELETE only: a POST, PUT or PATCH keeps its 416 (its
/// body, unread, closes the connection).
httplib::Server::HandlerResponse HttpServer::Impl::unparsed_range(const httplib::Request& req,
                                                                  httplib::Response& res) {
  auto& request = const_cast<httplib::Request&>(req);
  request.ranges.clear();
  res.status = 200;
  using Answer = httplib::Server::HandlerResponse;
  if (pre_route(req, res) == Answer::Handled) return Answer::Handled;
  const bool get = req.method == "GET" || req.method == "HEAD";
  if (!get && req.method != "DELETE") {
    res.set_header("Connection", "close");
    send_problem(res, 416, range_problem(req));
    return Answer::Handled;
  }
  const std::string range = req.get_header_value("Range");
  const bool bytes = range.size() >= 6 && std::equal(range.begin(), range.begin() + 6, "bytes=", [](char a, char b) {
                       return std::tolower(static_cast<unsigned char>(a)) == b;
                     });
  httplib::Ranges parsed;
  if (get && bytes && !httplib::detail::parse_range_header("bytes=" + range.substr(6), parsed))
    t_range = long_byte_range(std::string_view(range).substr(6)).value_or(kMalformed);
  else if (get && parsed.size() == 1) t_range = parsed.front();
  // A DELETE routed from here has its body (if any) unread: the connection ends after the answer.
  if (!get && has_body(req)) res.set_header("Connection", "close");
  const auto& routes = get ? get_routes : delete_routes;
  const auto route = std::find_if(routes.begin(), routes.end(),
                                  [&](const auto& r) { return std::regex_match(req.path, request.matches, r.first); });
  if (route == routes.end()) send_problem(res, 404, "no such route: " + req.method + " " + req.path);
  else route->second(req, res);
  return Answer::Handled;
}

void HttpServer::Impl::health(const httplib::Request&, httplib::Response& res) {
  Gauges g = jobs.gauges();
  std::size_t total = 0;
  for (const auto& [s, n] : g.jobs_by_state) total += n;
  send_json(res, 200,
            {{"status", "ok"},
             {"version", REMESHD_VERSION},
             {"uptime_seconds", seconds_since(started)},
             {"workers", g.workers},
             {"busy_workers", g.busy_workers},
             {"queue_depth", g.queue_depth},
             {"jobs", total},
             {"event_streams", streams.load()},
             // Large uploads being read and checked, and waiting for a slot (upload_gate.h).
             {"uploads", {{"reading", upload_gate->busy()}, {"waiting", upload_gate->waiting()},
                          {"slots", upload_gate->slots()}}}});
}

bool HttpServer::Impl::removed(const std::string& id) const {
  // The job's directory goes before its entry (expiry, the data cap): either means removed.
  return !jobs.record(id) || !jobs.stored(id);
}

std::optional<JobRecord> HttpServer::Impl::find_job(const httplib::Request& req, httplib::Response& res) {
  std::string id = req.matches.size() > 1 ? req.matches[1].str() : "";
  std::optional<JobRecord> rec;
  if (remesh::api::is_valid_job_id(id)) rec = jobs.record(id);
  if (!rec) send_problem(res, 404, "no job with id '" + id.substr(0, 64) + "'");
  return rec;
}

void HttpServer::Impl::post_job(const httplib::Request& req, httplib::Response& res,
                                const httplib::ContentReader& reader) {
  const std::size_t limit = options.max_upload_mb * kMiB;
  std::size_t total = 0;
  // Whatever the answer, a large upload's memory (its bytes, the mesh read from them: about three
  // times the file) goes back to the system a moment after it: QA saw the idle daemon at 60-190 MB
  // after uploads refused or run, against about 16 MB after jobs alone (malloc keeps what it freed).
  struct TrimAfterLarge {
    JobManager& jobs;
    const std::size_t& bytes;
    ~TrimAfterLarge() {
      if (bytes >= kTrimAfterBytes) jobs.trim_memory_soon();
    }
  } trim_after{jobs, total};
  std::string body, params_text, filename, part_type, part;
  bool too_big = false, params_too_big = false, over_budget = false;
  int mesh_parts = 0, params_parts = 0;  // a second part of either is refused, not joined to the first
  std::vector<std::string> other_parts;  // parts of other names, each once (refused, named)
  constexpr std::size_t kMaxNamedParts = 16;
  // A coded body's decoded bytes count in decoded_held while the request holds them (kCodedUploadsAtOnce).
  const bool coded_body = !t_body_coding.empty() || req.has_header("Content-Encoding");
  struct Held {
    std::atomic<std::size_t>& all;
    std::size_t mine = 0;
    ~Held() { all -= mine; }
  } held{decoded_held};
  auto count = [&](std::size_t n) {
    if (coded_body && !too_big) {
      if (decoded_held.fetch_add(n) + n > kCodedUploadsAtOnce * limit) {
        decoded_held -= n;
        over_budget = true;
        return false;
      }
      held.mine += n;
    }
    total += n;
    if (total > limit && !too_big) {
      too_big = true;
      std::string().swap(body);  // nothing of an over-limit upload is kept
      decoded_held -= std::exchange(held.mine, 0);
    }
    return total <= limit + kDrainBytes;  // past this, stop reading and close
  };
  bool ok = true;
  // A declared length is judged before any of the body is read when it is malformed or past what
  // would be drained (kDrainBytes; a body up to that is read, so that a client that sends before it
  // reads the answer gets the 413 rather than a reset): reading waited for bytes the client never
  // sent and answered after the 30-second read timeout, holding an HTTP thread all that time.
  if (req.has_header("Content-Length")) {
    // Digits only: pre_route refused any other Content-Length.
    const std::string declared = req.get_header_value("Content-Length");
    if (declared.size() > 18 || std::stoull(declared) > limit + kDrainBytes) {
      send_problem(res, 413, "the upload is larger than the limit of " + std::to_string(options.max_upload_mb) +
                                 " MiB (Content-Length " + declared.substr(0, 40) + ")");
      res.set_header("Connection", "close");
      return;
    }
  }
  // No body ('curl -X POST' without a file got its error after 30 s): nothing to read, and the
  // checks below say what is missing.
  if (!has_body(req)) {
    filename = req.get_param_value("filename");
    part_type = req.get_header_value("Content-Type");
  } else if (req.is_multipart_form_data()) {
    ok = reader(
        [&](const httplib::MultipartFormData& header) {
          part = header.name;
          if (part == "mesh" && ++mesh_parts == 1) {
            filename = header.filename;
            part_type = header.content_type;
          } else if (part == "params") {
            ++params_parts;
          } else if (std::find(other_parts.begin(), other_parts.end(), part) == other_parts.end() &&
                     other_parts.size() < kMaxNamedParts) {
            other_parts.push_back(part);
          }
          return true;
        },
        [&](const char* data, std::size_t n) {
          if (!count(n)) return false;
          if (too_big) return true;
          if (part == "mesh") {
            if (mesh_parts == 1) body.append(data, n);
          } else if (part == "params" && params_parts == 1) {
            if (params_text.size() + n > kMaxParamsBytes) params_too_big = true;
            else params_text.append(data, n);
          }
          return true;
        });
  } else {
    auto keep = [&](const char* data, std::size_t n) {
      if (!count(n)) return false;
      if (!too_big) body.append(data, n);
      return true;
    };
    if (t_body_coding.empty()) {
      ok = reader(keep);
    } else {
      BodyDecoder decoder(t_body_coding);
      std::size_t coded = 0;
      ok = reader([&](const char* data, std::size_t n) {
        coded += n;
        return decoder.feed(data, n, keep);
      });
      // Cut off; an empty body is left to the checks below ("mesh is empty"), as without a coding.
      if (ok && !too_big && coded > 0 && !decoder.complete()) ok = false;
    }
    filename = req.get_param_value("filename");
    part_type = req.get_header_value("Content-Type");
  }
  if (over_budget) {
    metrics.count_busy(Metrics::Busy::UploadSlots);
    res.set_header("Retry-After", "10");
    res.set_header("Connection", "close");  // the rest of the body is unread
    send_problem(res, 503, "the server is decoding other compressed uploads (" +
                               std::to_string(kCodedUploadsAtOnce * options.max_upload_mb) +
                               " MiB of them at once at most): try again in a few seconds, or send it uncompressed");
    return;
  }
  if (too_big || res.status == 413) {
    send_problem(res, 413, "the upload is larger than the limit of " + std::to_string(options.max_upload_mb) + " MiB");
    if (!ok) res.set_header("Connection", "close");
    return;
  }
  if (!ok) {
    // The rest of the body is unread (or its framing broken): it must not be read as a request.
    if (!res.has_header("Connection")) res.set_header("Connection", "close");
    std::string type = req.get_header_value("Content-Type");
    auto b = type.find("boundary=");
    if (req.is_multipart_form_data() && b != std::string::npos && type.find(';', b) != std::string::npos)
      send_problem(res, 400, "multipart/form-data: nothing may follow the boundary parameter (drop '" +
                                 type.substr(type.find(';', b)).substr(0, 40) + "')");
    else if (!t_body_coding.empty() || req.has_header("Content-Encoding"))
      send_problem(res, 400, "the request body could not be decoded as Content-Encoding '" +
                                 (t_body_coding.empty() ? req.get_header_value("Content-Encoding").substr(0, 40)
                                                        : t_body_coding) +
                                 "' (or it was cut off)");
    else
      send_problem(res, 400, "the request body could not be read (malformed or interrupted upload)");
    return;
  }

  std::vector<FieldError> errors;
  remesh::ParsedParams parsed;
  for (const auto& [name, parts] : {std::pair{"mesh", mesh_parts}, std::pair{"params", params_parts}})
    if (parts > 1)
      errors.push_back({name, "was sent " + std::to_string(parts) + " times; a job takes one (one remesh job per request)"});
  if (params_parts > 0) {
    std::vector<std::string> repeated;
    const json j = parse_noting_repeats(params_text, repeated);
    if (params_too_big) errors.push_back({"params", "is larger than 64 KiB"});
    else if (j.is_discarded()) errors.push_back({"params", "is not valid JSON: " + json_error(params_text)});
    else if (!j.is_object()) errors.push_back({"params", "must be a JSON object of the job's parameters"});
    else parsed = remesh::params_from_json(j);
    for (const std::string& key : repeated)
      errors.push_back({"params." + key.substr(0, 64), "is given more than once; give it once"});
    // The job's parameters come from one place: with a params part, the query holds none.
    const auto& names = remesh::param_names();
    for (const auto& [key, value] : req.params) {
      if (std::find(kUploadQueryKeys.begin(), kUploadQueryKeys.end(), key) != kUploadQueryKeys.end()) continue;
      const bool param = std::find(names.begin(), names.end(), key) != names.end();
      errors.push_back({key.substr(0, 64), param ? "is in the query and there is a params part: give every parameter in "
                                                   "the params part"
                                                 : "unknown parameter"});
    }
  } else {
    parsed = remesh::params_from_query(query_params(req), kUploadQueryKeys);
  }
  // A part of another name was dropped without a word (a typo 'param' lost its settings; `-F emin=1`
  // was answered "emin is required").
  for (const std::string& name : other_parts) {
    const auto& names = remesh::param_names();
    const bool param = std::find(names.begin(), names.end(), name) != names.end();
    errors.push_back({name.substr(0, 64),
                      param ? "is a part of its own: job parameters go in the JSON part 'params' (or all in the query)"
                      : name == "format" || name == "filename"
                          ? "is a part of its own: it goes in the query (?" + name + "=...), or comes from the mesh "
                                                                                     "part's file name"
                          : "unknown part: a job takes a file part 'mesh' and a JSON part 'params'"});
  }
  if (req.is_multipart_form_data() && mesh_parts == 0) errors.push_back({"mesh", "is required (a file field named 'mesh')"});
  else if (body.empty()) errors.push_back({"mesh", "is empty"});
  auto format = remesh::api::resolve_format(req.get_param_value("format"), filename, part_type, errors);
  bool params_readable = std::none_of(errors.begin(), errors.end(), [](const FieldError& e) { return e.field == "params"; });
  if (params_readable)
    for (const FieldError& e : remesh::validate_params(parsed, options.max_iterations)) errors.push_back(e);
  if (!errors.empty()) {
    send_problem(res, 422, "invalid request: see errors", errors);
    return;
  }

  // A large upload's mesh is read, and checked, while it holds a slot of the gate (upload_gate.h:
  // reading a mesh takes about ten times its size for a moment); it waits for one. Its bytes are in
  // already (decoded), so a client sending slowly holds no slot.
  std::optional<UploadGate::Pass> pass;
  if (body.size() >= kGatedUploadBytes) {
    UploadGate::Entry entry = upload_gate->enter();
    if (!entry.pass) {
      const bool closed = entry.refusal == UploadGate::Refusal::Closed;
      metrics.count_busy(closed ? Metrics::Busy::ShuttingDown : Metrics::Busy::UploadSlots);
      res.set_header("Retry-After", closed ? "5" : "10");
      send_problem(res, 503,
                   closed ? std::string("the server is shutting down")
                          : "the server is reading " + std::to_string(upload_gate->slots()) +
                                " other large uploads and no slot came free (--upload-slots, --upload-wait-seconds); "
                                "try again in a few seconds");
      return;
    }
    pass = std::move(entry.pass);
  }
  remesh::api::UploadLimits limits;
  limits.max_faces = options.max_faces;
  limits.max_iterations = options.max_iterations;
  limits.max_output_faces = options.max_output_faces;
  std::optional<remesh::api::PreparedJob> prepared;
  try {
    prepared.emplace(remesh::api::prepare_job(body, filename, format, parsed, limits));
  } catch (const remesh::ParamsError& e) {
    send_problem(res, remesh::api::problem_from_exception(e));
    return;
  } catch (const remesh::MeshError& e) {
    send_problem(res, remesh::api::problem_from_exception(e));
    return;
  } catch (const remesh::LimitError& e) {
    send_problem(res, remesh::api::problem_from_exception(e));
    return;
  }
  JobRecord& record = prepared->record;
  switch (jobs.submit(record, body)) {
    case JobManager::Submit::QueueFull:
      metrics.count_busy(Metrics::Busy::QueueFull);
      res.set_header("Retry-After", "10");
      send_problem(res, 503, "the job queue is full (" + std::to_string(options.queue_size) + " jobs); try again later");
      return;
    case JobManager::Submit::ShuttingDown:
      metrics.count_busy(Metrics::Busy::ShuttingDown);
      res.set_header("Retry-After", "5");
      send_problem(res, 503, "the server is shutting down");
      return;
    case JobManager::Submit::Accepted: break;
  }
  std::string location = std::string(kPrefix) + "/jobs/" + record.id;
  res.set_header("Location", location);
  auto current = jobs.record(record.id);
  send_json(res, 202, document(current ? *current : record));
}

void HttpServer::Impl::get_job(const httplib::Request& req, httplib::Response& res) {
  if (auto rec = find_job(req, res)) send_document(req, res, document(*rec));
}

void HttpServer::Impl::list_jobs(const httplib::Request& req, httplib::Response& res) {
  std::vector<FieldError> errors;
  std::optional<JobState> state;
  if (req.has_param("state") && !req.get_param_value("state").empty()) {
    state = remesh::api::parse_state(req.get_param_value("state"));
    if (!state) errors.push_back({"state", "must be one of queued, running, succeeded, failed, cancelling, cancelled"});
  }
  auto number = [&](const char* name, std::size_t fallback, std::size_t max) -> std::size_t {
    if (!req.has_param(name)) return fallback;
    std::string v = req.get_param_value(name);
    std::size_t n = 0;
    auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
    if (v.empty() || ec != std::errc() || p != v.data() + v.size() || n > max) {
      errors.push_back({name, "must be an integer 0.." + std::to_string(max)});
      return fallback;
    }
    return n;
  };
  std::size_t limit = number("limit", 50, 1000);
  std::size_t offset = number("offset", 0, 1'000'000'000);
  if (!errors.empty()) {
    send_problem(res, 422, "invalid query: see errors", errors);
    return;
  }
  JobManager::Page page = jobs.list(state, limit, offset);
  json list = json::array();
  for (const JobRecord& r : page.jobs) list.push_back(document(r));
  send_document(req, res, {{"jobs", list}, {"total", page.total}, {"limit", limit}, {"offset", offset}});
}

void HttpServer::Impl::delete_job(const httplib::Request& req, httplib::Response& res) {
  std::string id = req.matches[1].str();
  JobRecord after;
  auto outcome = remesh::api::is_valid_job_id(id) ? jobs.cancel(id, &after) : JobManager::Cancel::NotFound;
  switch (outcome) {
    case JobManager::Cancel::NotFound: send_problem(res, 404, "no job with id '" + id.substr(0, 64) + "'"); return;
    case JobManager::Cancel::Removed: res.status = 204; return;
    case JobManager::Cancel::Accepted: send_json(res, 202, document(after)); return;
  }
}

void HttpServer::Impl::events(const httplib::Request& req, httplib::Response& res) {
  auto rec = find_job(req, res);
  if (!rec) return;
  std::size_t open = ++streams;
  if (open > options.max_streams) {
    --streams;
    metrics.count_busy(Metrics::Busy::EventStreams);
    res.set_header("Retry-After", "5");
    send_problem(res, 503, "too many open event streams (" + std::to_string(options.max_streams) + "); retry later");
    return;
  }
  std::string last = req.get_header_value("Last-Event-ID");
  if (last.empty()) last = req.get_param_value("lastEventId");
  std::optional<JobState> state_before;
  auto cursor = jobs.start_cursor(rec->id, parse_last_event_id(last), state_before);
  if (!cursor) {
    --streams;
    send_problem(res, 404, "no job with id '" + rec->id + "'");
    return;
  }
  struct Stream {
    std::string id;
    std::size_t cursor;
    std::optional<JobState> state_before;
    bool started = false;
    std::chrono::steady_clock::time_point deadline;
  };
  auto stream = std::make_shared<Stream>(Stream{rec->id, *cursor, state_before, false,
                                                std::chrono::steady_clock::now() +
                                                    std::chrono::milliseconds(static_cast<long long>(
                                                        options.stream_lifetime_seconds * 1000))});
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  double heartbeat = options.heartbeat_seconds;
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, stream, heartbeat](std::size_t, httplib::DataSink& sink) {
        if (!sink.is_writable()) return false;  // the client left (0.11.4 would spin otherwise)
        std::string out;
        if (!stream->started) {
          stream->started = true;
          out += sse_retry(3000);
          if (stream->state_before) out += sse_state(*stream->state_before);
        }
        // Wait for events up to the heartbeat (or the stream's end), in slices of kLeftCheckSeconds
        // between which a client that left is noticed: its stream slot (--max-streams) and HTTP
        // thread were held until the next heartbeat's write failed.
        const auto now = std::chrono::steady_clock::now();
        const auto until = std::min(stream->deadline, now + std::chrono::milliseconds(static_cast<long long>(heartbeat * 1000)));
        JobManager::Batch batch;
        for (;;) {
          const double left = std::chrono::duration<double>(until - std::chrono::steady_clock::now()).count();
          batch = jobs.poll(stream->id, stream->cursor, std::max(0.0, std::min(kLeftCheckSeconds, left)));
          if (!batch.found || !batch.events.empty() || batch.ended || batch.shutting_down || left <= kLeftCheckSeconds)
            break;
          if (!sink.is_writable()) return false;
        }
        if (!batch.found) {  // removed while streaming
          out += sse_comment("job removed");
          sink.write(out.data(), out.size());
          sink.done();
          return true;
        }
        for (std::size_t i = 0; i < batch.events.size(); ++i)
          out += batch.events[i].kind == JobEvent::Kind::State ? sse_state(batch.events[i].state)
                                                               : sse_iteration(batch.rows[i]);
        stream->cursor = batch.cursor;
        bool finish = false;
        if (batch.ended) {
          out += sse_end(batch.state);
          finish = true;
        } else if (batch.shutting_down) {
          out += sse_comment("server shutting down") + sse_retry(2000);
          finish = true;
        } else if (std::chrono::steady_clock::now() >= stream->deadline) {
          out += sse_comment("stream lifetime reached; reconnect with Last-Event-ID") + sse_retry(1000);
          finish = true;
        } else if (out.empty()) {
          out = sse_comment("ping");
        }
        if (!sink.write(out.data(), out.size())) return false;
        t_streamed_bytes += out.size();
        if (finish) sink.done();
        return true;
      },
      [this](bool) { --streams; });
}

void HttpServer::Impl::result(const httplib::Request& req, httplib::Response& res) {
  auto rec = find_job(req, res);
  if (!rec) return;
  std::string mesh = req.has_param("mesh") ? req.get_param_value("mesh") : "remeshed";
  std::string format = req.has_param("format") ? req.get_param_value("format") : "obj";
  std::vector<FieldError> errors;
  const std::vector<std::string>* formats = nullptr;
  if (mesh == "remeshed" || mesh == "input") formats = &remesh::api::remeshed_formats();
  else if (mesh == "dual") formats = &remesh::api::dual_formats();
  else errors.push_back({"mesh", "must be remeshed, dual or input"});
  if (formats && std::find(formats->begin(), formats->end(), format) == formats->end()) {
    std::string allowed;
    for (const auto& f : *formats) allowed += (allowed.empty() ? "" : ", ") + f;
    errors.push_back({"format", "must be one of " + allowed + " for mesh=" + mesh});
  }
  if (!errors.empty()) {
    send_problem(res, 422, "invalid query: see errors", errors);
    return;
  }
  if (mesh != "input" && rec->state != JobState::Succeeded) {
    Problem p = make_problem(409, "the job is " + std::string(remesh::api::state_name(rec->state)) +
                                      "; results exist only when it succeeded");
    p.body["state"] = remesh::api::state_name(rec->state);
    if (rec->error) p.body["error"] = *rec->error;
    send_problem(res, p);
    return;
  }
  std::filesystem::path path;
  try {
    path = jobs.file(rec->id, mesh + "." + format);
  } catch (const std::range_error& e) {
    // The format cannot hold this mesh (STL, GLB and glTF store float32: a mesh placed beyond 3.4e38).
    send_problem(res, 422, std::string("this mesh cannot be written as ") + format + ": " + e.what());
    return;
  } catch (const std::exception& e) {
    // Deleted meanwhile (its directory went while the file was made): a 404, as a moment later.
    if (removed(rec->id)) {
      send_problem(res, 404, "the job was removed while its file was being made");
      return;
    }
    // The reason (it names paths on the server) goes to the log only.
    log.error("handler", {str("path", req.path), str("job", rec->id), str("error", e.what())});
    send_problem(res, 500, "cannot make the " + format + " file of this job (the service's log says why)");
    return;
  }
  // A file gone or damaged: a job removed meanwhile (DELETE, expiry, the data cap, which remove the
  // files before the job) takes them at any moment, and then it is a 404; else the data directory
  // was damaged under the service (no result is 0 bytes: such a file was served as a 200).
  auto unavailable = [&] {
    res.headers.erase("ETag");
    res.headers.erase("Cache-Control");
    if (removed(rec->id)) return send_problem(res, 404, "the file is gone (the job was removed)");
    std::error_code ec;
    const bool exists = std::filesystem::exists(path, ec);
    log.error("handler", {str("path", req.path), str("job", rec->id),
                          str("error", (exists ? "empty or unreadable " : "missing ") + path.string())});
    send_problem(res, 500, "the job's " + mesh + "." + format + " file is " + (exists ? "empty or unreadable" : "missing") +
                               " in the service's data directory (removed or damaged there)");
  };
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) return unavailable();
  std::string etag = "\"" + rec->id + "-" + mesh + "-" + format + "-" + std::to_string(size) + "\"";
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", "private, no-cache");
  // A list, possibly over several header lines (RFC 9110 5.3): all of them.
  std::string inm;
  for (std::size_t i = 0; i < req.get_header_value_count("If-None-Match"); ++i)
    inm += (i ? ", " : "") + req.get_header_value("If-None-Match", i);
  if (!inm.empty() && (inm == "*" || inm.find(etag) != std::string::npos)) {
    res.status = 304;
    return;
  }
  // Opened after the 304 (a revalidation opens no file); the file may go in between (then not a 500
  // naming its path: the answer above). Once open, it is served whole even if the job goes.
  auto file = OpenFile::open(path);
  if (!file || file->size() == 0) return unavailable();
  res.set_header("Content-Disposition",
                 remesh::api::content_disposition("attachment", rec->filename, "-" + mesh + "." + format));
  res.set_header("Accept-Ranges", "bytes");
  auto f = remesh::parse_format(format);
  send_file(req, res, std::move(file), f ? std::string(remesh::mime_type(*f)) : "application/octet-stream");
}

void HttpServer::Impl::stats(const httplib::Request& req, httplib::Response& res) {
  auto rec = find_job(req, res);
  if (!rec) return;
  std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
  if (format != "json" && format != "csv") {
    send_problem(res, 422, "invalid query: see errors", {{"format", "must be json or csv"}});
    return;
  }
  auto rows = jobs.rows(rec->id);
  if (!rows) {
    send_problem(res, 404, "no job with id '" + rec->id + "'");
    return;
  }
  if (format == "csv") {
    res.set_header("Content-Disposition", remesh::api::content_disposition("inline", rec->filename, "-stats.csv"));
    send_ranged(req, res, remesh::stats_to_csv(*rows), "text/csv; charset=utf-8", true);
    return;
  }
  send_document(req, res, {{"rows", *rows}});
}

void HttpServer::Impl::static_files(const httplib::Request& req, httplib::Response& res) {
  if (req.path.rfind("/api/", 0) == 0 || req.path == "/api") {
    send_problem(res, 404, "no such route: " + req.method + " " + req.path);
    return;
  }
  const auto file = static_file(web_root, req.path);
  auto opened = file ? OpenFile::open(*file) : nullptr;  // null too when the file went meanwhile
  if (!opened) {
    if (!file && (req.path == "/" || req.path == "/index.html"))
      send_ranged(req, res, missing_web_root_page(web_root), "text/html; charset=utf-8", true);
    else
      send_problem(res, 404, "no such file: " + req.path.substr(0, 200));
    return;
  }
  res.set_header("Cache-Control", "no-cache");
  send_file(req, res, std::move(opened), mime_for(*file));
}

HttpServer::HttpServer(const Options& options, JobManager& jobs, Metrics& metrics, Logger& log,
                       std::filesystem::path web_root)
    : impl_(std::make_unique<Impl>(options, jobs, metrics, log, std::move(web_root))) {
  impl_->setup();
}

HttpServer::~HttpServer() = default;

int HttpServer::bind() {
  const Options& o = impl_->options;
  int port = o.port;
  if (port == 0) port = impl_->server.bind_to_any_port(o.host);
  else if (!impl_->server.bind_to_port(o.host, port)) port = -1;
  if (port <= 0) throw std::runtime_error("cannot listen on " + o.host + ":" + std::to_string(o.port));
  impl_->server.widen_backlog();
  return port;
}

bool HttpServer::serve() {
  const bool ok = impl_->server.listen_after_bind();
  {
    std::lock_guard lock(impl_->served_mutex);
    impl_->served = true;
  }
  impl_->served_changed.notify_all();
  return ok;
}

bool HttpServer::stop(double grace_seconds) {
  impl_->jobs.wake_all();
  if (impl_->upload_gate) impl_->upload_gate->close();
  impl_->server.stop();
  std::unique_lock lock(impl_->served_mutex);
  return impl_->served_changed.wait_for(lock, std::chrono::duration<double>(grace_seconds),
                                        [this] { return impl_->served; });
}

std::size_t HttpServer::open_streams() const { return impl_->streams.load(); }

}  // namespace remeshd
