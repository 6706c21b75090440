#include "log.h"

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
      bool quote = f.value.empty() || f.value.find_first_of(" \"=\t\n") != std::string::npos;
      line += " " + f.key + "=" + (quote ? nlohmann::json(f.value).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) : f.value);
    }
  }
  line += '\n';
  std::lock_guard lock(mutex_);
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
}

}  // namespace remeshd
