#pragma once
/// \file stopping_rule.h
/// Not in the thesis, whose runs do their n iterations: when equalize() stops, and which mesh it
/// returns. With the cleanup on (Params::cleanup), a run
///   - converges: every edge inside [e_min, e_max], then a few polishing iterations (kPolishMax,
///     stopping_rule.cpp) that return the polished mesh with the most regular vertices;
///   - stalls: the count of edges outside has reached no new low for a few iterations (kStallSpan);
///   - or reaches n (and with run_all_iterations it always does).
/// One that ends with edges outside returns the mesh of its low, after the final cleanup. Without
/// the cleanup a run stops at its first mesh with every edge inside (unless run_all_iterations).
/// The rule also holds the rows of the polishing iterations back until it is known whether they
/// stand.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stop_token>
#include <vector>

#include "core/mesh.h"
#include "remesh/equalize.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/params.h"

namespace remesh {

/// The run's mesh, as the stopping rule works on it (equalize.cpp's run does the work, with its
/// reference surface and its timers).
class RunMesh {
 public:
  /// A copy of the mesh as it is, to return to.
  virtual MeshSnapshot snapshot() const = 0;
  /// The mesh becomes the snapshot's mesh again.
  virtual void restore(const MeshSnapshot& snapshot) = 0;
  /// The statistics of the mesh as it is, with the iteration number and counters of `counted`.
  virtual IterationStats measured(const IterationStats& counted) const = 0;
  /// The final cleanup (kFinalCleanupRounds, equalize.cpp) of the mesh as it is, timed as the
  /// run's cleanup; its counts are added to `row` (not measured). Returns its fixes.
  virtual std::size_t final_cleanup(IterationStats& row) = 0;

 protected:
  ~RunMesh() = default;
};

class StoppingRule {
 public:
  /// `run`, `params` (as_run's) and `on_iteration` must outlive the rule.
  StoppingRule(RunMesh& run, const Params& params, const OnIteration& on_iteration, std::stop_token stop);

  struct Verdict {
    /// Completed: go on (or, at n, the run ends so); Converged or Stalled: the run stops.
    Outcome outcome = Outcome::Completed;
    bool ending = false;    ///< the run's last iteration: stopping, or the n-th
    bool restored = false;  ///< the best mesh (and its row) replaced this iteration's
  };

  /// Judges iteration i by its `row`, the statistics of the mesh after the iteration's steps. It
  /// may change the mesh and the row: the best mesh restored, or the mesh of the low with the final
  /// cleanup (end_at_low); `row` then describes the mesh as it is. `cleanup_started`: the full
  /// interval cleanup runs in every iteration (from then on lows of edges outside are counted).
  Verdict judge(int i, IterationStats& row, bool cleanup_started);

  /// The outcome of a run whose last iteration's row (after its ending steps) is `row`.
  Outcome outcome(const Verdict& verdict, const IterationStats& row) const;

  /// Reports the row through on_iteration, or holds it back while polishing (a row that is not the
  /// last); the rows held are reported before it once they stand.
  void report(const IterationStats& row, bool ending);
  /// Reports the rows held back.
  void flush();

  /// Has the run converged once (its best mesh with every edge inside kept): it is polishing.
  bool polishing() const { return best_.has_value(); }
  /// The iteration of the last new low of edges outside (0: none yet).
  int last_low() const { return fewest_at_; }
  /// The row of the best mesh (polishing() only).
  const IterationStats& best_row() const { return best_->row; }

 private:
  struct Kept {
    MeshSnapshot mesh;
    IterationStats row;
  };

  void keep_low(int i, const IterationStats& row, bool cleanup_started);
  Verdict polish(int i, IterationStats& row);
  void end_at_low(IterationStats& row);

  RunMesh& run_;
  const Params& params_;
  const OnIteration& on_iteration_;
  std::stop_token stop_;
  std::size_t fewest_outside_ = SIZE_MAX;  ///< fewest edges outside since the cleanup started, and when
  int fewest_at_ = 0;
  /// Polishing (see kPolishMax): the best mesh so far with every edge inside.
  std::optional<Kept> best_;
  std::optional<Kept> fewest_;  ///< the mesh of the low of edges outside, once the cleanup runs
  int converged_at_ = 0, outside_since_ = 0;  ///< first convergence; iterations in a row with edges outside
  std::vector<IterationStats> held_;          ///< rows of the polishing iterations, not yet reported
};

}  // namespace remesh
