#pragma once
/// \file progress.h
/// What a remeshing run shows while it goes: a progress bar on stderr when stderr is a terminal,
/// and the thesis' table rows (iteration, vertices, edges, average, deviation, regular, small, big,
/// plus inside %) on stdout every few iterations and for the last one.

#include <chrono>
#include <string>

#include "remesh/equalize.h"

namespace remesh::cli {

/// The table's header line and one row, fixed-width, without a newline.
std::string table_header();
std::string table_row(const IterationStats& row);

class Progress {
 public:
  /// `total`: the iterations asked for (>= 1); `quiet`: show nothing; `every`: table period (>= 1).
  Progress(int total, bool quiet, int every = 5);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Call after each iteration (from the thread running the remesher's callback).
  void update(const IterationStats& row);
  /// Clears the bar and prints the last row if the table has not shown it yet.
  void finish();

 private:
  void draw_bar();
  void clear_bar();

  int total_;
  bool quiet_;
  int every_;
  bool bar_;
  bool header_printed_ = false;
  bool last_printed_ = true;
  bool has_row_ = false;
  IterationStats last_{};
  std::chrono::steady_clock::time_point start_;
};

}  // namespace remesh::cli
