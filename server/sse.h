#pragma once
/// \file sse.h
/// Server-sent event frames as remeshd writes them (text/event-stream).

#include <optional>
#include <string>
#include <string_view>

#include "api/job.h"

namespace remeshd {

/// "event: state\ndata: {\"state\":\"running\"}\n\n"
std::string sse_state(remesh::api::JobState state);
/// "event: iteration\nid: 3\ndata: {row}\n\n"
std::string sse_iteration(const remesh::IterationStats& row);
/// "event: end\ndata: {\"state\":\"succeeded\"}\n\n"
std::string sse_end(remesh::api::JobState state);
/// "retry: <ms>\n\n"
std::string sse_retry(int milliseconds);
/// ": <text>\n\n"
std::string sse_comment(std::string_view text);
/// Parses a Last-Event-ID value (an iteration number >= 0); nullopt if empty or not a number.
std::optional<int> parse_last_event_id(std::string_view value);

}  // namespace remeshd
