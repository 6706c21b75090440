/// \file cmd_remesh.cpp
/// `remesh IN OUT --emin A --emax B [...]`: Algorithm 1 on IN, OUT written even when cancelled;
/// optionally the dual of the result projected onto IN, and the statistics rows as CSV or JSON.

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <string_view>

#include "args.h"
#include "commands.h"
#include "dual/dual_stats.h"
#include "dual/relax_bonds.h"
#include "dual/trivalent_dual.h"
#include "interrupt.h"
#include "io/summary.h"
#include "api/json_codec.h"
#include "progress.h"
#include "remesh/equalize.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/reference_surface.h"
#include "remesh/self_intersections.h"
#include "remesh/surface_distance.h"

namespace remesh::cli {
namespace {

/// Does `path` end in `ext` (".csv"), in any case (OUT's extension is read so too)?
bool ends_with_ignoring_case(const std::string& path, std::string_view ext) {
  if (path.size() <= ext.size()) return false;
  for (std::size_t k = 0; k < ext.size(); ++k)
    if (std::tolower(static_cast<unsigned char>(path[path.size() - ext.size() + k])) != ext[k]) return false;
  return true;
}
bool stats_as_json(const std::string& path) { return ends_with_ignoring_case(path, ".json"); }

const std::vector<OptionSpec> kSpec = {
    {"emin", "A", "smallest allowed edge length, > 0 (required, or --bond-min and --bond-max)"},
    {"emax", "B", "largest allowed edge length, > A (required, or --bond-min and --bond-max)"},
    {"bond-min", "A", "instead of --emin/--emax: the dual's shortest bond, > 0 (edges of A*sqrt(3) or longer)"},
    {"bond-max", "B", "instead of --emin/--emax: the dual's longest bond, > A (edges up to B*sqrt(3))"},
    {"iterations", "N", "iterations n, 1..1000 (default 100)"},
    {"rings", "K", "rings k of the low-pass filter, 1..4 (default 2)"},
    {"relax-every", "PR", "replace the reference surface every PR iterations; 0 = never (default 0)"},
    {"flip-factor", "F", "a flip may lower the min angle to F times its old value, 0..1 (default 0.5)"},
    {"all-iterations", "", "run all N iterations instead of stopping early (converged or stalled)"},
    {"protect-tips", "", "never move tips (ears, horns, spikes) to mend edges: closer to the input there, more edges outside"},
    {"keep-creases", "", "keep the input's sharp edges (over 75 degrees) exactly, as CAD models need; more edges may stay outside"},
    {"more-regular", "", "flip further ahead for valence-6 vertices (about 2 points more; hexagons in the dual); tips cut a little more"},
    {"dual", "DUAL_OUT", "also write the trivalent dual of the result, projected onto IN"},
    {"relax-dual", "", "relax the dual's bonds toward the middle of [A, B] / sqrt(3) (atom lattices); needs --dual"},
    {"stats", "FILE", "write the per-iteration statistics to FILE.csv or FILE.json"},
    {"threads", "T", "worker threads; 0 = all cores (default 0; results do not depend on it)"},
    {"max-faces", "N", "refuse runs whose estimated output exceeds N faces (default 20000000), and, when given, inputs over N faces; 0 = no limit"},
    {"weld", "", "weld duplicate vertices at the same position while reading"},
    {"quiet", "", "print nothing but errors"},
};

/// The CLI option a Params field comes from ("relax_every" -> "--relax-every").
std::string option_for(std::string field) {
  std::replace(field.begin(), field.end(), '_', '-');
  return "--" + field;
}

/// An error about a parameter said in the CLI's terms: its field, and the interval's fields named in
/// its message, as options ("--bond-max: must be greater than --bond-min").
FieldError in_cli_terms(FieldError e) {
  e = renamed({std::move(e)}, {{"bond_min", "--bond-min"}, {"bond_max", "--bond-max"}, {"emin", "--emin"}, {"emax", "--emax"}})
          .front();
  if (!e.field.starts_with("--")) e.field = option_for(e.field);
  return e;
}

struct Job {
  std::string in, out;
  std::optional<std::string> dual_out, stats_out;
  Params params;
  bool bonds = false;  ///< the interval given as the dual's bonds (--bond-min, --bond-max)
  ReadOptions read;
  bool quiet = false;
};

Job parse_job(const std::vector<std::string>& args) {
  const Args a = parse_args(args, kSpec, 2, 2);
  Job job;
  job.in = a.positional[0];
  job.out = a.positional[1];
  // Still reported alone, before the values are read (like parse_args' errors): a run without an
  // interval is refused whatever else is wrong, and the one line names both when both are missing.
  // The interval is --emin and --emax, or the dual's bonds --bond-min and --bond-max.
  job.bonds = a.has("bond-min") || a.has("bond-max");
  const char* low = job.bonds ? "bond-min" : "emin";
  const char* high = job.bonds ? "bond-max" : "emax";
  if (job.bonds && (a.has("emin") || a.has("emax")))
    throw UsageError("give either --emin and --emax (edge lengths) or --bond-min and --bond-max (the dual's bond "
                     "lengths), not both");
  if (!a.has(low) || !a.has(high))
    throw UsageError(std::string("missing required option") +
                     (!a.has(low) && !a.has(high) ? std::string("s --") + low + " and --" + high
                                                  : std::string(" --") + (a.has(low) ? high : low)) +
                     (job.bonds ? "" : " (or --bond-min and --bond-max, the dual's bond lengths)"));
  // Every value is read even after a bad one, so that all bad options are reported at once, with
  // the range errors of the ones that did parse (README: one line per bad option).
  std::vector<FieldError> errors;
  std::set<std::string> unreadable;  // the options whose value did not parse
  auto read = [&](auto get) {
    try {
      return get();
    } catch (const ValueError& e) {
      errors.push_back({"--" + e.option(), e.problem()});
      unreadable.insert("--" + e.option());
      return decltype(get())();
    }
  };
  Params& p = job.params;
  if (auto v = read([&] { return a.get_double(low); })) p.e_min = job.bonds ? edge_for_bond(*v) : *v;
  if (auto v = read([&] { return a.get_double(high); })) p.e_max = job.bonds ? edge_for_bond(*v) : *v;
  // A bond past the largest double / sqrt(3) has no edge length (check() would call it not finite).
  for (const auto& [option, edge] : {std::pair{low, p.e_min}, std::pair{high, p.e_max}})
    if (job.bonds && a.has(option) && !unreadable.count(std::string("--") + option) && !std::isfinite(edge)) {
      errors.push_back({std::string("--") + option, "is too large: its edges, bond * sqrt(3), are past the largest number"});
      unreadable.insert(std::string("--") + option);
    }
  if (auto v = read([&] { return a.get_int("iterations", INT_MIN, INT_MAX); })) p.iterations = static_cast<int>(*v);
  if (auto v = read([&] { return a.get_int("rings", INT_MIN, INT_MAX); })) p.rings = static_cast<int>(*v);
  if (auto v = read([&] { return a.get_int("relax-every", INT_MIN, INT_MAX); })) p.relax_every = static_cast<int>(*v);
  if (auto v = read([&] { return a.get_double("flip-factor"); })) p.flip_factor = *v;
  if (auto v = read([&] { return a.get_int("threads", 0, 1024); })) p.threads = static_cast<unsigned>(*v);
  if (auto v = read([&] { return a.get_int("max-faces", 0, LLONG_MAX); })) {
    p.max_output_faces = static_cast<std::size_t>(*v);
    job.read.max_faces = static_cast<std::size_t>(*v);
  }
  p.run_all_iterations = a.has("all-iterations");
  p.protect_tips = a.has("protect-tips");
  p.keep_creases = a.has("keep-creases");
  p.more_regular = a.has("more-regular");
  p.relax_dual = a.has("relax-dual");
  job.read.weld = a.has("weld");
  job.quiet = a.has("quiet");
  job.dual_out = a.get("dual");
  job.stats_out = a.get("stats");

  for (const auto& checked : job.bonds ? in_bond_terms(check(p)) : check(p)) {
    FieldError e = in_cli_terms(checked);
    // An option whose value did not parse kept its default, which check() may refuse too (e_min
    // 0): it has its line already.
    if (!unreadable.count(e.field)) errors.push_back(std::move(e));
  }
  if (!errors.empty()) throw ParamsError(std::move(errors));
  require_input_file(job.in);
  require_output_format(job.out);
  if (job.dual_out) require_output_format(*job.dual_out);
  if (p.relax_dual && !job.dual_out) throw UsageError("--relax-dual: relaxes the dual's bonds, so it needs --dual DUAL_OUT");
  if (job.stats_out) {
    const auto& s = *job.stats_out;
    if (!stats_as_json(s) && !ends_with_ignoring_case(s, ".csv"))
      throw UsageError("--stats: '" + s + "' must end in .csv or .json");
    try {
      require_writable(s);
    } catch (const UsageError& e) {
      throw UsageError(std::string("--stats: ") + e.what());
    }
  }
  // Before the run: the dual, then the statistics, would silently replace a file written before them.
  require_distinct_outputs({{"OUT", job.out}, {"--dual", job.dual_out}, {"--stats", job.stats_out}});
  require_not_input(job.in, "--dual", job.dual_out);
  require_not_input(job.in, "--stats", job.stats_out);
  return job;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
  if (!f.flush()) throw std::runtime_error("write failed: " + path);
}

/// The input's pairs of faces that cross each other (find_input_self_intersections), or nullopt when
/// too many of its faces overlap to count them, for the summary's crossing line beside the result's.
using InputCrossings = std::optional<std::size_t>;

void print_final(const TriMesh& mesh, const Job& job, const Result& result, const std::optional<DualStats>& dual,
                 const std::optional<BondRelaxation>& relaxed, const InputCrossings& input_crossings,
                 const std::optional<SurfaceDistance>& to_input) {
  const IterationStats q = measure(mesh, job.params.e_min, job.params.e_max, job.params.threads);
  const MeshSummary s = summarize(mesh);
  std::printf("result: %zu vertices, %zu edges, %zu faces\n", s.vertices, s.edges, s.faces);
  std::printf("  edges inside [%g, %g]: %.3f %% (%zu small, %zu big)\n", job.params.e_min, job.params.e_max,
              100.0 * q.inside_fraction, q.small, q.big);
  if (result.thin.outside > 0)
    std::printf("  in thin parts:        %zu of the %zu edges outside (the input is thinner than %g = 2 e_min / "
                "sqrt(3) there: too thin for edges in the interval)\n",
                result.thin.in_thin_parts, result.thin.outside, result.thin.limit);
  if (result.thin.outside > 0)
    std::printf("  irregular valence:    %zu of the %zu edges outside (an end of valence other than 6, or 4 on the "
                "boundary: a 5-7 pair strains the edges around it by 10-15 %%, more than a tight interval allows)\n",
                result.thin.at_irregular, result.thin.outside);
  if (result.thin.outside > 0 && job.params.keep_creases)
    std::printf("  at kept creases:      %zu of the %zu edges outside (an end on a crease --keep-creases holds: creases "
                "or their corners closer together than the interval allows)\n",
                result.thin.at_creases, result.thin.outside);
  if (result.layered)
    std::printf("  crossing faces:       not counted: the surface lies over itself throughout, as a part duplicated "
                "in place or stacked shells do (not untangled)\n");
  else if (result.crossing_pairs) {
    std::string input = input_crossings ? std::to_string(*input_crossings) + " pairs" : "not counted";
    // A run that ran out of iterations with edges far from the interval (a QA run: 1 iteration,
    // 37 % inside) may leave crossings where the input is neither crossed nor thin: said so.
    const bool unsettled = result.outcome == Outcome::Completed && q.inside_fraction < 0.9;
    if (*result.crossing_pairs > 0)
      std::printf("  crossing faces:       %zu pairs (the input: %s; faces passing through each other: where the input "
                  "crosses itself, or where parts are thinner than the edges%s)\n",
                  *result.crossing_pairs, input.c_str(),
                  unsettled ? ", or where the run ended before its mesh settled: more --iterations" : "");
    else if (input_crossings != std::optional<std::size_t>(0))
      std::printf("  crossing faces:       0 pairs (the input: %s)\n", input.c_str());
    else
      std::printf("  crossing faces:       0 pairs\n");
  }
  std::printf("  regular vertices:     %.2f %%\n", q.regular_percent);
  if (const ThinParts& t = result.thin; t.vertices_thinner > 0 && t.vertices_thicker > 0) {
    auto percent = [](std::size_t part, std::size_t whole) { return 100.0 * double(part) / double(whole); };
    std::printf("  by thickness:         %.2f %% where the input is at least %g = 2 e_max thick, %.2f %% of the %zu "
                "vertices%s in thinner parts (a tube a few edges round needs a 5-7 pair wherever it widens or "
                "narrows)\n",
                percent(t.regular_thicker, t.vertices_thicker), t.vertex_limit,
                percent(t.regular_thinner, t.vertices_thinner), t.vertices_thinner,
                t.sampled ? " of a sample" : "");
  }
  std::printf("  edge length:          mean %.6g, deviation %.4g, min %.6g, max %.6g\n", q.mean, q.deviation,
              s.min_edge, s.max_edge);
  if (const auto& d = to_input; d && d->diagonal > 0) {
    std::printf("  distance to input:    %.4g at most (%.3g %% of its bounding-box diagonal): the result lies within "
                "%.4g of the input, the input within %.4g of the result (at vertices, edge midpoints and face "
                "centres)\n",
                d->hausdorff(), 100.0 * d->relative(), d->result_to_input, d->input_to_result);
  }
  if (const auto& t = result.triangles; t && t->faces > 0)
    std::printf("  triangles:            angles %.1f to %.1f degrees, %.3f %% with one under 30, %.3f %% obtuse; "
                "radius ratio min %.3f, mean %.4f\n",
                t->min_angle, t->max_angle, 100.0 * t->below_30, 100.0 * t->above_90, t->min_radius_ratio,
                t->mean_radius_ratio);
  if (dual) {
    std::fflush(stdout);
    print_dual_stats(std::cout, *dual);
    std::cout.flush();
  }
  if (relaxed && relaxed->bonds > 0) {
    const double n = static_cast<double>(relaxed->bonds);
    std::printf("  bonds relaxed:        %d iteration%s, inside %.3f %% -> %.3f %%, %.2f s\n", relaxed->iterations,
                relaxed->iterations == 1 ? "" : "s", 100.0 * static_cast<double>(relaxed->inside_before) / n,
                100.0 * static_cast<double>(relaxed->inside_after) / n, relaxed->seconds);
  }
  std::printf("  outcome:              %s after %d iteration%s, %.2f s\n", outcome_name(result.outcome),
              result.iterations_done, result.iterations_done == 1 ? "" : "s", result.seconds);
  // Where the time went (Result::phases); "other" is the rest: statistics rows, snapshots.
  std::printf("  seconds by step:      %s\n", describe_phases(result.phases, result.seconds).c_str());
  std::fflush(stdout);
}

}  // namespace

int run_remesh(const std::vector<std::string>& args) {
  if (wants_help(args)) {
    std::cout << format_help(
        "remesh IN OUT (--emin A --emax B | --bond-min A --bond-max B) [OPTIONS]",
        "Remeshes IN by iterative edge equalization so that its edge lengths lie in [A, B] and writes\n"
        "OUT (.obj .off .ply .stl .glb .gltf .xyz .lammps). Shows the statistics every 5 iterations and a\n"
        "final quality summary. Ctrl-C stops after the current step and still writes the (valid) mesh.\n"
        "For dual edges (bond lengths) in [a, b], give --bond-min a --bond-max b instead: the primal\n"
        "interval is then [a*sqrt(3), b*sqrt(3)].",
        kSpec);
    return 0;
  }
  const Job job = parse_job(args);
  // From here on Ctrl-C asks for a stop (and no longer kills the program before the mesh is
  // written); one during reading makes equalize() return at once with the input as it was.
  std::stop_source stop;
  const InterruptGuard guard(stop);
  LoadedMesh loaded = read_mesh_file(job.in, job.read);
  // A mesh the remesher refuses gets its one line before the repairs are listed.
  check_mesh_size(loaded.mesh);
  check_vertex_stars(loaded.mesh);
  // Before equalize() checks them in the engine's terms: said with the options given.
  if (auto errors = check_interval_against(loaded.mesh, job.params, job.bonds); !errors.empty()) {
    for (auto& e : errors) e = in_cli_terms(std::move(e));
    throw ParamsError(std::move(errors));
  }
  if (job.bonds) check_output_estimate(loaded.mesh, job.params, "--bond-max too small for this mesh");
  if (!job.quiet) print_repairs(std::cerr, loaded.repairs);
  std::optional<ReferenceSurface> reference;
  if (job.dual_out) reference.emplace(loaded.mesh);

  TriMesh& mesh = loaded.mesh;
  // The input as read (repairs made), for the summary's distance to it, measured after the run:
  // kept as points and triangles (48 bytes a vertex; a copy of the mesh, ~250, took a 400 000-face
  // input's peak 185 -> 236 MB).
  std::optional<MeshSnapshot> input_kept;
  if (!job.quiet) input_kept.emplace(mesh);
  // The input's crossing faces, for the summary (a search of the input: nefertiti's 100 000 faces
  // about 0.05 s).
  InputCrossings input_crossings;
  if (!job.quiet)
    if (const auto pairs = find_input_self_intersections(mesh, job.params.threads)) input_crossings = pairs->size();
  std::vector<IterationStats> rows;
  Progress progress(job.params.iterations, job.quiet);
  const Result result = equalize(
      mesh, job.params,
      [&](const IterationStats& row) {
        rows.push_back(row);
        progress.update(row);
      },
      stop.get_token());
  progress.finish();

  write_mesh_file(to_soup(mesh), job.out);
  std::optional<DualStats> dual_summary;
  std::optional<BondRelaxation> relaxed;
  bool relax_stopped = false;
  if (job.dual_out) {
    PolyMesh dual = trivalent_dual(mesh, &*reference);
    if (job.params.relax_dual)
      relaxed = relax_bonds(dual, job.params.e_min, job.params.e_max, *reference, job.params.threads, stop.get_token());
    // Stopped by Ctrl-C (it returns at once then); one after it, while the files are written, is not.
    relax_stopped = relaxed && stop.stop_requested();
    write_mesh_file(to_soup(dual), *job.dual_out);
    if (!job.quiet) dual_summary = dual_stats(dual, job.params.e_min, job.params.e_max);  // for the summary only
  }
  if (job.stats_out) {
    const bool json = stats_as_json(*job.stats_out);
    write_text_file(*job.stats_out, json ? nlohmann::json(rows).dump(2) + "\n" : stats_to_csv(rows));
  }
  if (!job.quiet) {
    // Not after Ctrl-C: the user wants out (nefertiti at 831 000 faces: 2 s more to exit).
    std::optional<SurfaceDistance> to_input;
    if (!stop.stop_requested()) {
      TriMesh input;
      input_kept->rebuild(input);
      input_kept.reset();
      to_input = surface_distance(mesh, input, job.params.threads);
    }
    print_final(mesh, job, result, dual_summary, relaxed, input_crossings, to_input);
  }
  if (result.outcome == Outcome::Cancelled) {
    std::cerr << "remesh: cancelled after " << result.iterations_done << " iterations; wrote the partial mesh to "
              << job.out << "\n";
    return 1;
  }
  // Ctrl-C after the run, while the dual's bonds were relaxed: the dual is written as far as it got.
  if (relax_stopped) {
    std::cerr << "remesh: cancelled while relaxing the dual's bonds; wrote the mesh to " << job.out
              << " and the partly relaxed dual to " << *job.dual_out << "\n";
    return 1;
  }
  return 0;
}

}  // namespace remesh::cli
