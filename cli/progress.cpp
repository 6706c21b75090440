/// \file progress.cpp
#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace remesh::cli {

std::string table_header() {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%5s %10s %10s %10s %10s %8s %8s %8s %8s", "iter", "vertices", "edges", "average",
                "deviation", "regular", "small", "big", "inside");
  return buf;
}

std::string table_row(const IterationStats& r) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%5d %10zu %10zu %10.5g %10.4g %7.2f%% %8zu %8zu %7.3f%%", r.iteration, r.vertices,
                r.edges, r.mean, r.deviation, r.regular_percent, r.small, r.big, 100.0 * r.inside_fraction);
  return buf;
}

Progress::Progress(int total, bool quiet, int every)
    : total_(std::max(total, 1)),
      quiet_(quiet),
      every_(std::max(every, 1)),
      bar_(!quiet && isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

void Progress::update(const IterationStats& row) {
  if (quiet_) return;
  last_ = row;
  has_row_ = true;
  last_printed_ = false;
  if (row.iteration % every_ == 0 || row.iteration == total_) {
    clear_bar();
    if (!header_printed_) {
      std::cout << table_header() << "\n";
      header_printed_ = true;
    }
    std::cout << table_row(row) << std::endl;
    last_printed_ = true;
  }
  draw_bar();
}

void Progress::finish() {
  if (quiet_) return;
  clear_bar();
  if (has_row_ && !last_printed_) {
    if (!header_printed_) std::cout << table_header() << "\n";
    header_printed_ = true;
    std::cout << table_row(last_) << std::endl;
    last_printed_ = true;
  }
  bar_ = false;
}

void Progress::draw_bar() {
  if (!bar_) return;
  constexpr int kWidth = 30;
  const int done = std::clamp(last_.iteration, 0, total_);
  const int filled = done * kWidth / total_;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  std::fprintf(stderr, "\r[%s] %d/%d  inside %.2f%%  %.1f s\033[K", bar.c_str(), done, total_,
               100.0 * last_.inside_fraction, seconds);
  std::fflush(stderr);
}

void Progress::clear_bar() {
  if (!bar_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

}  // namespace remesh::cli
