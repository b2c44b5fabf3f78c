#pragma once
// The forced-response stage of a case (`shroudsim frf`, the last stage of `run`): the forced
// model of the case (forced_model.hpp), the frequency response traced over the range
// (forced/frequency_response.hpp), its result files and its run.json section.
//
// Result files (docs/contract.md): frf.csv (every point: frequency, amplitude, the linear
// amplitude, Newton iterations, harmonic amplitudes, piece), loops.csv (hysteresis loops of
// the first 10 pairs at the peak), peaks.csv (the located resonance peaks); run.json "frf"
// (points, peaks, status, the solver's statistics, the energy-balance check) and, with
// hbm.harmonics or hbm.time_samples = "auto", "auto" (every trial of the search).
//
// The stage never reports success for a curve that fails its own checks: a continuation that
// stopped before the end of the range or an energy balance beyond hbm.energy_tolerance is
// returned as a failure (the caller draws what was written, then exits 3).
#include <string>

#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

/// How the forced-response stage ended.
struct ForcedResponseOutcome {
  /// Empty: the curve passed its checks. Otherwise why it failed them (the result files hold
  /// the points that were traced).
  std::string failure;
};

/// Runs the forced response of ctx.config into ctx.out_dir: frf.csv, loops.csv, peaks.csv,
/// the report's "frf" (and "auto") sections and the "frf" stage, ctx.frf_curve. With
/// hbm.harmonics / hbm.time_samples = "auto", the search of forced/discretization_search.hpp:
/// each trial a full forced response into <out>/auto/H=..__N=../, the accepted trial's files
/// copied to ctx.out_dir. Throws InputError for inputs the forced response cannot use (a zero
/// excitation, a contact pair the model cannot evaluate) and NumericalError when no curve can
/// be started.
ForcedResponseOutcome run_forced_response(Context& ctx);

}  // namespace shroudsim::pipeline
