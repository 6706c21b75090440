#include "remesh/stopping_rule.h"

#include <utility>

namespace remesh {

namespace {

/// Iterations without a new low of edges outside the interval (cleanup on) before a run stops as
/// stalled. A stalled run returns the mesh of its low (the fewest edges outside; among those, the
/// most regular vertices): the count wanders by a few edges around it (cow: 2 edges at iteration
/// 27, 2 to 9 in the next 6). The span is kStallSpan, or kShortStallSpan once the low is at most
/// kFewOutside of the edges: a few edges pinned by the input's geometry, which more iterations do
/// not win (the final cleanup does what can be done). Measured (Table 4.2 setup): a span of 3
/// instead of 6 gives the same meshes on every refinement run that stalls (cow, cheese, nefertiti,
/// camelhead, bunny_zipper; 2-3 iterations less, nefertiti 10.8 -> 9.0 s), but ends the
/// simplifications, which creep down by a few edges every 3-6 iterations, early: bunny 99.95 ->
/// 99.59 % inside and 85.9 -> 80.4 % regular, cow 95.5 -> 93.4 %, camelhead 99.73 -> 99.56 %.
/// The share rule kept 6 for those (bunny's low is 0.15 % of its edges until its last iterations),
/// at 0.1 %. With the interval guard (kSteadyAfter) they no longer creep, and the share is 1 %:
/// the same meshes on every run of bench --spread (12 meshes refined, 10 simplified) but bunny's
/// simplification (99.862 -> 99.899 % inside, mean of five), and stalled runs end sooner (cheese
/// refinement 1.84 -> 1.62 s, cow 0.58 -> 0.55 s, camelhead's simplification 0.52 -> 0.45 s). A span
/// of 3 everywhere: cheese's simplification 64.75 -> 63.44 % inside, and a small cone
/// (equalize_test's horn, 3 of its 231 edges outside at the low) stalls instead of converging.
constexpr int kStallSpan = 6;
constexpr int kShortStallSpan = 3;
constexpr double kFewOutside = 0.01;
int stall_span(std::size_t low, std::size_t edges) {
  return static_cast<double>(low) <= kFewOutside * static_cast<double>(edges) ? kShortStallSpan : kStallSpan;
}

/// Polishing: after the first iteration with every edge inside, iterations go on while they raise
/// the share of regular vertices: at least one, at most kPolishMax, stopping after an iteration with
/// every edge inside that gained less than kPolishGain points over the best such mesh, or after
/// kPolishGrace iterations in a row with an edge outside. The best mesh with every edge inside (most
/// regular vertices) is returned; a last polished mesh with edges outside but more regular vertices
/// gets the final cleanup first, and is returned when that puts every edge inside. The cleanup that
/// wins the last edges back costs regularity (eight: 85.1 % regular at its first convergence), and
/// one polishing iteration does not always repay it (eight: 87.5 %, spot 89.4 %, kitten 89.2 %;
/// measured in the Table 4.2 setup).
constexpr int kPolishMax = 3;
constexpr double kPolishGain = 0.25;
constexpr int kPolishGrace = 3;

bool all_inside(const IterationStats& row) { return row.small == 0 && row.big == 0; }

}  // namespace

StoppingRule::StoppingRule(RunMesh& run, const Params& params, const OnIteration& on_iteration,
                           std::stop_token stop)
    : run_(run), params_(params), on_iteration_(on_iteration), stop_(std::move(stop)) {}

// Is this the last iteration? Converged: every edge inside; with the cleanup on, after the
// polishing iterations (kPolishMax), returning the polished mesh with the most regular vertices.
// Stalled: with the cleanup on, the count of edges outside has not reached a new low for
// stall_span() iterations (a few edges pinned by the input's geometry, e.g. where two sheets
// touch): more iterations would change nothing but the time spent.
StoppingRule::Verdict StoppingRule::judge(int i, IterationStats& row, bool cleanup_started) {
  keep_low(i, row, cleanup_started);
  Verdict verdict;
  if (!params_.cleanup) {
    if (!params_.run_all_iterations && all_inside(row)) verdict.outcome = Outcome::Converged;
  } else if (params_.run_all_iterations) {
    // No early stop (the outcome stays Completed); the n-th iteration ends as a run that reaches
    // n does, at its low.
    if (i == params_.iterations) end_at_low(row);
  } else {
    if (all_inside(row) && !best_) {
      best_ = Kept{run_.snapshot(), row};
      converged_at_ = i;
      fewest_.reset();  // no longer needed
    } else if (best_) {
      verdict = polish(i, row);
    } else if (cleanup_started && i - fewest_at_ >= stall_span(fewest_outside_, row.edges)) {
      verdict.outcome = Outcome::Stalled;
    }
    if (!best_ && (verdict.outcome == Outcome::Stalled || i == params_.iterations)) end_at_low(row);
  }
  if (verdict.restored) {
    run_.restore(best_->mesh);
    row = best_->row;
    held_.clear();
  }
  verdict.ending = verdict.outcome != Outcome::Completed || i == params_.iterations;
  return verdict;
}

void StoppingRule::keep_low(int i, const IterationStats& row, bool cleanup_started) {
  const std::size_t outside = row.small + row.big;
  if (cleanup_started && outside < fewest_outside_) fewest_outside_ = outside, fewest_at_ = i;
  // Keep the mesh of the low until the first mesh with every edge inside (then `best` is returned);
  // with run_all_iterations, which has no `best`, through the whole run, meshes with every edge
  // inside included.
  if (cleanup_started && (!all_inside(row) || params_.run_all_iterations) && !best_ && params_.cleanup &&
      outside == fewest_outside_ &&
      (!fewest_ || fewest_->row.small + fewest_->row.big > outside ||
       row.regular_percent > fewest_->row.regular_percent))
    fewest_ = Kept{run_.snapshot(), row};
}

/// An iteration after the first convergence (kPolishMax): converged, or go on polishing.
StoppingRule::Verdict StoppingRule::polish(int i, IterationStats& row) {
  Verdict verdict;
  const bool inside = all_inside(row);
  const bool gained = inside && row.regular_percent >= best_->row.regular_percent + kPolishGain;
  outside_since_ = inside ? 0 : outside_since_ + 1;
  if (inside && !gained) {
    verdict.outcome = Outcome::Converged;
    verdict.restored = row.regular_percent < best_->row.regular_percent;
  } else if (i - converged_at_ >= kPolishMax || outside_since_ >= kPolishGrace || i == params_.iterations) {
    verdict.outcome = Outcome::Converged;
    // The last polished mesh, with a few edges outside but more regular vertices than the
    // best, gets the final cleanup (kFinalCleanupRounds) before the best is restored instead.
    // Measured (bench --spread, 120 runs): bunny refined at [1.2, 1.8] 87.82 -> 89.67 %
    // regular (its three polishing iterations reached 89.1-89.6 % with 1-2 edges outside),
    // fandisk simplified at [1.21, 1.81] 85.37 -> 87.30 %; the 118 other runs unchanged.
    // The final cleanup in every polishing iteration instead stopped some polishing sooner:
    // 16 other runs changed, 12 of them for the worse (eight -0.4, fandisk -0.4 points).
    bool inside_now = inside;
    if (!inside && row.regular_percent >= best_->row.regular_percent + kPolishGain && !stop_.stop_requested()) {
      run_.final_cleanup(row);
      row = run_.measured(row);
      inside_now = all_inside(row);
    }
    verdict.restored = !inside_now || row.regular_percent < best_->row.regular_percent;
  } else if (gained) {
    best_ = Kept{run_.snapshot(), row};
    flush();  // the rows before this one stand
  }
  return verdict;
}

/// A run that ends with edges outside (stalled, or n reached; with run_all_iterations, any run at
/// its n-th iteration) returns the mesh of its low: `row` (this iteration's) then describes it (its
/// counters stay this iteration's), so that the last row is the returned mesh's. Then the final
/// cleanup (kFinalCleanupRounds) works on it.
void StoppingRule::end_at_low(IterationStats& row) {
  const std::size_t outside = row.small + row.big;
  const std::size_t low = fewest_ ? fewest_->row.small + fewest_->row.big : SIZE_MAX;
  if (low < outside || (low == outside && fewest_->row.regular_percent > row.regular_percent)) {
    run_.restore(fewest_->mesh);
    row = run_.measured(row);
  }
  if (stop_.stop_requested() || all_inside(row)) return;
  if (run_.final_cleanup(row) > 0) row = run_.measured(row);
}

Outcome StoppingRule::outcome(const Verdict& verdict, const IterationStats& row) const {
  Outcome outcome = verdict.outcome;
  // The outcome of a run that stopped early describes the mesh returned, which this row does: the
  // final cleanup or the untangling's can mend a stalled run's last edges (nefertiti's
  // simplification), and the untangling's last round can leave an edge outside.
  if (outcome == Outcome::Stalled || outcome == Outcome::Converged)
    outcome = all_inside(row) ? Outcome::Converged : Outcome::Stalled;
  // A stop asked for during the last iteration's ending steps (the final cleanup cut short, the
  // snap and the untangling skipped) is a cancelled run, not a finished one: the caller must not
  // take the mesh for a result (the service marked such a job succeeded, the CLI exited 0).
  if (verdict.ending && stop_.stop_requested()) outcome = Outcome::Cancelled;
  return outcome;
}

void StoppingRule::report(const IterationStats& row, bool ending) {
  // The best mesh's row was kept before its iteration's seconds were known: restored, it was
  // reported with 0 seconds.
  if (best_ && best_->row.iteration == row.iteration) best_->row.seconds = row.seconds;
  // Rows of the polishing iterations wait until it is known whether they stand (rows after the
  // best mesh do not when it is restored).
  if (best_ && !ending) {
    held_.push_back(row);
    return;
  }
  flush();
  if (on_iteration_) on_iteration_(row);
}

void StoppingRule::flush() {
  if (on_iteration_)
    for (const IterationStats& r : held_) on_iteration_(r);
  held_.clear();
}

}  // namespace remesh
