#pragma once
/// \file http_server.h
/// The HTTP face of remeshd (cpp-httplib hidden behind this interface; only http_server.cpp
/// includes httplib.h): routes of api/openapi.yaml, auth, CORS, limits, SSE, static files,
/// request logging and metrics.

#include <filesystem>
#include <memory>
#include <string>

#include "job_manager.h"
#include "log.h"
#include "metrics.h"
#include "options.h"

namespace remeshd {

class HttpServer {
 public:
  HttpServer(const Options& options, JobManager& jobs, Metrics& metrics, Logger& log,
             std::filesystem::path web_root);
  ~HttpServer();

  /// Binds to options.host:options.port (port 0: any free port). Returns the bound port; throws
  /// std::runtime_error if binding fails.
  int bind();
  /// Serves until stop() is called. Returns false if the server failed.
  bool serve();
  /// Stops accepting and ends open streams, then waits up to `grace_seconds` for serve() to return,
  /// which it does once the requests in flight are answered. Returns whether it did: a client can
  /// hold a connection as long as it likes (see main.cpp).
  bool stop(double grace_seconds);
  /// Open SSE streams.
  std::size_t open_streams() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The OpenAPI document (api/openapi.yaml, embedded at build time).
const std::string& openapi_yaml();

}  // namespace remeshd
