#pragma once
/// \file run_process.h
/// Runs a program as a subprocess and captures its exit code, stdout and stderr (for CLI tests).

#include <string>
#include <vector>

namespace remesh::test {

struct ProcessResult {
  int exit_code = -1;  ///< the exit status; 128 + signal if it was killed by a signal
  std::string out, err;
};

/// Runs `program` with `args` (no shell), waits for it, returns what it printed.
/// If `interrupt_after_ms` > 0, sends SIGINT to the child after that many milliseconds.
ProcessResult run_process(const std::string& program, const std::vector<std::string>& args,
                          int interrupt_after_ms = 0);

}  // namespace remesh::test
