#include "sse.h"

#include <charconv>

#include "api/json_codec.h"

namespace remeshd {

std::string sse_state(remesh::api::JobState state) {
  return "event: state\ndata: {\"state\":\"" + std::string(remesh::api::state_name(state)) + "\"}\n\n";
}

std::string sse_iteration(const remesh::IterationStats& row) {
  return "event: iteration\nid: " + std::to_string(row.iteration) + "\ndata: " + nlohmann::json(row).dump() + "\n\n";
}

std::string sse_end(remesh::api::JobState state) {
  return "event: end\ndata: {\"state\":\"" + std::string(remesh::api::state_name(state)) + "\"}\n\n";
}

std::string sse_retry(int milliseconds) { return "retry: " + std::to_string(milliseconds) + "\n\n"; }

std::string sse_comment(std::string_view text) { return ": " + std::string(text) + "\n\n"; }

std::optional<int> parse_last_event_id(std::string_view value) {
  while (!value.empty() && value.front() == ' ') value.remove_prefix(1);
  while (!value.empty() && value.back() == ' ') value.remove_suffix(1);
  int n = 0;
  auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
  if (value.empty() || ec != std::errc() || p != value.data() + value.size() || n < 0) return std::nullopt;
  return n;
}

}  // namespace remeshd
