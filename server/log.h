#pragma once
/// \file log.h
/// One line per event on stderr, as text (`2026-11-22T03:00:00.000Z INFO request method=GET ...`)
/// or as JSON ({"ts":..., "level":..., "event":..., fields...}). Thread-safe.

#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace remeshd {

/// A field value is written as given (text) or as a JSON string/number (json).
struct LogField {
  std::string key;
  std::string value;
  bool number = false;
};

class Logger {
 public:
  explicit Logger(bool json = false) : json_(json) {}
  /// Writes one line: `level` INFO/WARN/ERROR, `event` a short name ("request", "job").
  void log(const char* level, const std::string& event, const std::vector<LogField>& fields);
  void info(const std::string& event, const std::vector<LogField>& fields) { log("INFO", event, fields); }
  void warn(const std::string& event, const std::vector<LogField>& fields) { log("WARN", event, fields); }
  void error(const std::string& event, const std::vector<LogField>& fields) { log("ERROR", event, fields); }

 private:
  bool json_;
  std::mutex mutex_;
};

/// A numeric field.
LogField num(std::string key, double value);
/// A text field.
inline LogField str(std::string key, std::string value) { return {std::move(key), std::move(value), false}; }

}  // namespace remeshd
