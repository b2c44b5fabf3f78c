#pragma once
// Studies over a case (`shroudsim study`). A study point is the case with the point's values
// as --set overrides (after the command line's own), run by the caller's case runner (the
// app's `run`: every stage the case asks for) in its own folder <out>/<key=value__...>/ with
// its own run.json, quietly and with one thread each; points run in parallel on --threads
// workers, their cost measured as the CPU time of their thread.
//
//   - the [study] vary grid: the Cartesian product of the value lists (first key slowest),
//     every point validated before any runs -> study.csv (status, peak amplitude and
//     frequency, points, seconds and folder of every point);
//   - `study --convergence` (Context::convergence): every knob of the accuracy/speed trade
//     (study/trade_design.hpp) varied one at a time around the case's own setting, each
//     against its finest value -> trade.csv and, for the mesh ladder, the observed order and
//     extrapolated peak in run.json "mesh_convergence" (docs/contact_patches.md).
//
// Under `mpirun -n K` (or srun) the points are shared with the other ranks of the job, which
// run serve_study (distributed/task_pool.hpp): a worker that finishes takes the next point;
// rank 0 writes the tables. The first point runs alone either way: it fills the mesh and
// mode caches of <case dir>/.cache that the other points read.
//
// A failed point is recorded (status and reason in its folder's run.json and in the table)
// and the study goes on; the caller exits 3 when any failed.
#include <functional>
#include <string>

#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

/// Runs one case in a prepared context and returns its exit status (0, 2, 3), or throws
/// InputError / NumericalError.
using CaseRunner = std::function<int(Context&)>;

struct StudyOutcome {
  std::string warning;  ///< empty: every point (row) ran; otherwise how many failed
};

/// The study of ctx.config (the vary grid, the convergence study when ctx.convergence, or the
/// sampled study of [study] sample) into ctx.out_dir; the report's "study" section. Sweep and
/// convergence points run `run_case` (every stage of the case); the points of a sampled study,
/// whose result is the forced response, run `run_forced` (the stages the forced response needs,
/// not the Campbell diagram or the modes' output files of every sample). Throws InputError for
/// an empty or too large grid or a sweep point whose values do not make a valid case.
StudyOutcome run_study(Context& ctx, const CaseRunner& run_case, const CaseRunner& run_forced);

/// A serving rank of `mpirun -n K shroudsim study` (rank > 0): runs the points rank 0 hands
/// out, on `threads` workers, into their folders of rank 0's staging folder (a file system
/// every rank sees), with the same runners; returns the exit status rank 0 released it with.
int serve_study(int threads, const CaseRunner& run_case, const CaseRunner& run_forced);

}  // namespace shroudsim::pipeline
