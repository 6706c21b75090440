#pragma once
/// \file errors.h
/// Typed exceptions of the engine. The API layer maps them to HTTP statuses, the CLI to exit codes:
///   MeshError       -> 422 / exit 3   (unreadable, unsupported or invalid input mesh)
///   ParamsError     -> 422 / exit 2   (invalid parameters; carries every bad field)
///   LimitError      -> 413 / exit 3   (the job would exceed a configured size limit)

#include <stdexcept>
#include <string>
#include <vector>

namespace remesh {

/// One invalid field of a parameter set, named as the API and CLI name it (e.g. "emin").
struct FieldError {
  std::string field;
  std::string message;
};

/// The input mesh cannot be read or is not a mesh we can work on. The message names the problem
/// and where it is (line, element index, count), on one line.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parameters failed validation; `errors()` lists every invalid field.
class ParamsError : public std::invalid_argument {
 public:
  explicit ParamsError(std::vector<FieldError> errors)
      : std::invalid_argument(join(errors)), errors_(std::move(errors)) {}
  const std::vector<FieldError>& errors() const { return errors_; }

 private:
  static std::string join(const std::vector<FieldError>& errors) {
    std::string s = "invalid parameters:";
    for (const auto& e : errors) s += " " + e.field + ": " + e.message + ";";
    if (!errors.empty()) s.pop_back();
    return s;
  }
  std::vector<FieldError> errors_;
};

/// A job would exceed a configured limit (faces in, estimated faces out, ...).
class LimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace remesh
