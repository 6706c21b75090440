/// \file cmd_remesh_unavailable.cpp
/// Stand-in for the remeshing command in a build without the remesher library (remesh_equalize).

#include <stdexcept>

#include "commands.h"

namespace remesh::cli {

int run_remesh(const std::vector<std::string>&) {
  throw std::runtime_error("this build of remesh has no remesher (remesh_equalize was not built)");
}

}  // namespace remesh::cli
