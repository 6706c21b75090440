#pragma once
/// \file routes.h
/// The routes remeshd serves, as OpenAPI paths. http_server.cpp registers exactly these (plus the
/// static-file fallback for the web page); tests/server checks them against api/openapi.yaml.

#include <string>

namespace remeshd {

struct RouteSpec {
  const char* method;  ///< "GET", "POST", "DELETE"
  const char* path;    ///< OpenAPI path, parameters as {name}
};

inline constexpr RouteSpec kRoutes[] = {
    {"GET", "/"},
    {"GET", "/healthz"},
    {"GET", "/metrics"},
    {"GET", "/api/v1/openapi.yaml"},
    {"POST", "/api/v1/jobs"},
    {"GET", "/api/v1/jobs"},
    {"GET", "/api/v1/jobs/{id}"},
    {"DELETE", "/api/v1/jobs/{id}"},
    {"GET", "/api/v1/jobs/{id}/events"},
    {"GET", "/api/v1/jobs/{id}/result"},
    {"GET", "/api/v1/jobs/{id}/stats"},
};

/// The httplib pattern of an OpenAPI path: each {param} becomes ([^/]+), '.' is escaped.
inline std::string route_pattern(const std::string& path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '{') {
      i = path.find('}', i);
      out += "([^/]+)";
    } else if (path[i] == '.') {
      out += "\\.";
    } else {
      out += path[i];
    }
  }
  return out;
}

}  // namespace remeshd
