/// \file main.cpp
/// `remesh`: the first argument picks the command (info, convert, dual, help); anything else is the
/// remeshing command `remesh IN OUT --emin A --emax B ...`.

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "args.h"
#include "commands.h"
#include "core/errors.h"

#ifndef REMESH_VERSION
#define REMESH_VERSION "unknown"
#endif

namespace {

/// Messages go out on one line whatever the exception carried.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

const char* const kOverview =
    "Usage: remesh COMMAND [ARGS...]\n"
    "       remesh IN OUT --emin A --emax B [OPTIONS]\n"
    "       remesh IN OUT --bond-min A --bond-max B [OPTIONS]\n"
    "\n"
    "Iterative edge-length equalization of triangle meshes and their trivalent duals.\n"
    "\n"
    "Commands:\n"
    "  IN OUT --emin A --emax B   remesh IN so its edges lie in [A, B], write OUT ('remesh help remesh')\n"
    "  info MESH                  print the summary of a mesh and the repairs made while reading it\n"
    "  convert IN OUT             convert between formats (by extension: obj off ply stl glb gltf xyz lammps)\n"
    "  dual IN OUT                write the trivalent dual of a mesh\n"
    "  help [COMMAND]             show help for a command\n"
    "\n"
    "Every command accepts --help. 'remesh --version' prints the version.\n"
    "Exit codes: 0 ok, 2 bad arguments, 3 bad input mesh, 1 other errors.\n";

int dispatch(const std::string& command, const std::vector<std::string>& rest) {
  using namespace remesh::cli;
  if (command == "info") return run_info(rest);
  if (command == "convert") return run_convert(rest);
  if (command == "dual") return run_dual(rest);
  if (command == "remesh") return run_remesh(rest);
  throw UsageError("unknown command '" + command + "'");
}

int run(int argc, char** argv) {
  using namespace remesh::cli;
  // Output piped into a program that exits early (`remesh ... | head -1`) must not end the run before
  // the mesh is written: without this SIGPIPE killed it (exit 141, no file). Writes to the closed
  // pipe then fail quietly.
  std::signal(SIGPIPE, SIG_IGN);
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << kOverview;
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h") {
    std::cout << kOverview;
    return 0;
  }
  if (args[0] == "--version") {
    std::cout << "remesh " << REMESH_VERSION << "\n";
    return 0;
  }
  if (args[0] == "help") {
    if (args.size() == 1) {
      std::cout << kOverview;
      return 0;
    }
    return dispatch(args[1], {"--help"});
  }
  const std::string& first = args[0];
  if (first == "info" || first == "convert" || first == "dual")
    return dispatch(first, std::vector<std::string>(args.begin() + 1, args.end()));
  // A bare word that is no file is a mistyped command rather than an input mesh.
  if (first[0] != '-' && first.find_first_of("./") == std::string::npos && !std::filesystem::exists(first))
    throw UsageError("unknown command '" + first + "'");
  return run_remesh(args);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const remesh::cli::UsageError& e) {
    std::cerr << "remesh: " << one_line(e.what()) << " (see 'remesh --help')\n";
    return 2;
  } catch (const remesh::ParamsError& e) {
    for (const auto& f : e.errors()) std::cerr << "remesh: " << f.field << ": " << one_line(f.message) << "\n";
    return 2;
  } catch (const remesh::MeshError& e) {
    std::cerr << "remesh: bad input mesh: " << one_line(e.what()) << "\n";
    return 3;
  } catch (const remesh::LimitError& e) {
    std::cerr << "remesh: too large: " << one_line(e.what()) << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "remesh: error: " << one_line(e.what()) << "\n";
    return 1;
  } catch (...) {
    std::cerr << "remesh: error: unknown failure\n";
    return 1;
  }
}
