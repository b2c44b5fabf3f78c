#pragma once
// Shapes and contact maps of a traced forced response (docs/contract.md, "Shapes and contact
// maps"; response.shapes, response.shapes_at_hz): at every resonance peak (the sampled
// maximum when none was located) and at each crossing of the frequencies the user lists,
//   contact_map.csv  per shape and pair: normal load range, slip amplitude, stick / slip /
//                    open fractions of the period, energy dissipated per cycle;
// and for a sector
//   frf.vtu          the operating deflection shape of every sector node as complex harmonic
//                    fields (<shape>_u_h<n>_re_m / _im_m) and its amplitude over the period;
//   frf_<shape>.pvd  the shape over one period in kFrames frames (frf_frames/), for ParaView
//                    to animate; frf.pvd: the same for the largest peak;
//   contact.vtu      the contact map on the shroud face nodes (contact_pair = -1 elsewhere).
// The displacements are those about the static state, from the same receptance as the harmonic
// balance (frf::sector_displacements), so their response and contact rows are the curve's.
#include <vector>

#include "forced/frequency_response.hpp"
#include "forced/reduced_equations.hpp"
#include "hbm/contact_evaluator.hpp"
#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

/// Writes the files above into ctx.out_dir (atomically); warnings (a listed frequency the
/// curve does not reach) go to the report. Records the "shapes" stage.
void write_shapes(Context& ctx, const forced::ForcedModel& model, hbm::ContactEvaluator& evaluator,
                  forced::ReducedEquations& equations, const forced::FrequencyResponse& response);

}  // namespace shroudsim::pipeline
