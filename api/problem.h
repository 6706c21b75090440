#pragma once
/// \file problem.h
/// RFC 9457 problem documents (application/problem+json) as the service answers errors.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace remesh::api {

/// An error answer: status and the problem+json body.
struct Problem {
  int status = 500;
  nlohmann::json body;
};

/// {type: "about:blank", title: <reason phrase>, status, detail} plus `errors: [{field, message}]`
/// when given (validation).
Problem make_problem(int status, std::string detail, const std::vector<FieldError>& errors = {});

/// The standard reason phrase of a status ("Unprocessable Content" for 422, ...).
std::string status_title(int status);

/// Maps an exception from reading or validating a job to a problem: MeshError -> 422 (detail = the
/// message), ParamsError -> 422 with its fields, LimitError -> 413, anything else -> 500.
Problem problem_from_exception(const std::exception& e);

}  // namespace remesh::api
