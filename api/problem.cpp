#include "problem.h"

#include "json_codec.h"

namespace remesh::api {

std::string status_title(int status) {
  switch (status) {
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 416: return "Range Not Satisfiable";
    case 422: return "Unprocessable Content";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 501: return "Not Implemented";
    case 505: return "HTTP Version Not Supported";
    case 503: return "Service Unavailable";
    default: return "Error";
  }
}

Problem make_problem(int status, std::string detail, const std::vector<FieldError>& errors) {
  nlohmann::json body = {{"type", "about:blank"},
                         {"title", status_title(status)},
                         {"status", status},
                         {"detail", std::move(detail)}};
  if (!errors.empty()) body["errors"] = errors;
  return {status, std::move(body)};
}

Problem problem_from_exception(const std::exception& e) {
  if (auto* p = dynamic_cast<const ParamsError*>(&e)) return make_problem(422, p->what(), p->errors());
  if (dynamic_cast<const MeshError*>(&e)) return make_problem(422, e.what());
  if (dynamic_cast<const LimitError*>(&e)) return make_problem(413, e.what());
  return make_problem(500, std::string("internal error: ") + e.what());
}

}  // namespace remesh::api
