#include "log.h"

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "api/job.h"
#include "api/json_codec.h"

namespace remeshd {

LogField num(std::string key, double value) { return {std::move(key), remesh::format_double(value), true}; }

void Logger::log(const char* level, const std::string& event, const std::vector<LogField>& fields) {
  std::string line;
  std::string ts = remesh::api::iso8601(remesh::api::now_seconds());
  if (json_) {
    nlohmann::json j = {{"ts", ts}, {"level", level}, {"event", event}};
    for (const LogField& f : fields) {
      if (f.number && f.value != "null") j[f.key] = nlohmann::json::parse(f.value, nullptr, false);
      else j[f.key] = f.value;
    }
    line = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  } else {
    line = ts + " " + level + " " + event;
    for (const LogField& f : fields) {
      // Quoted (JSON string escapes) when it has a space, a quote, '=' or any control byte: a raw
      // carriage return or NUL from a request path made a line that looked like two, or like binary.
      bool quote = f.value.empty() || std::any_of(f.value.begin(), f.value.end(), [](char c) {
                     return static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == ' ' || c == '"' || c == '=';
                   });
      line += " " + f.key + "=" + (quote ? nlohmann::json(f.value).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) : f.value);
    }
  }
  line += '\n';
  std::lock_guard lock(mutex_);
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
}

}  // namespace remeshd
