#pragma once
// The forced-response model of a case (lumped or FE sector), its contact evaluator options and
// continuation settings: what `frf`, `study` and the benchmarks build a forced response from.
#include <memory>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"
#include "continuation/arclength.hpp"
#include "forced/frequency_response.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/linear_part.hpp"
#include "hbm/contact_evaluator.hpp"
#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

using forced::ForcedModel;

/// structure.type = "lumped": M, K, C and [[contact.elements]].
ForcedModel make_lumped_model(const io::Case& c);
/// The harmonic indices a sector case's forced response needs: h_n = n m mod Nb, n = 1..H,
/// sorted, unique (h = 0 of the static harmonic comes from K_0, not from modes), and with
/// sector_stability_requested every index 0..Nb/2.
std::vector<int> forced_harmonic_indices(const io::Case& c);
/// Whether a case's forced response is judged by shooting (docs/physics.md section 9): a lumped
/// model with response.stability on and response.stability_method "shooting", or "auto" with
/// friction at any contact element.
bool judged_by_shooting(const io::Case& c);

/// An FE sector with response.stability on and response.stability_method = "hill": its forced
/// stage computes the modes of every harmonic index 0..Nb/2 (the perturbation families).
bool sector_stability_requested(const io::Case& c);
/// Why a case's forced response gets no stability analysis although response.stability is on
/// (an FE sector with stability_method "auto", docs/physics.md section 9); empty when it gets one.
std::string sector_stability_refusal(const io::Case& c);
/// structure.type = "sector": modal receptances of the sector, shroud contact pairs.
ForcedModel make_sector_model(Context& ctx);
/// The excitation and response points of a sector case: InputError (naming the key) when the
/// nearest node is clamped or the point lies off the sector. `run` checks them on the mesh
/// before any modal work.
void check_forced_points(const io::Case& c, const mesh::Mesh& mesh);
/// The contact evaluator options of a case (H, N, model, update, Jacobian kind).
hbm::ContactEvaluatorOptions evaluator_options(const io::Case& c, int threads);
/// The [continuation] settings of a case's forced response (forced/frequency_response.hpp).
forced::FrequencyResponseSettings frequency_response_settings(const io::Case& c);

}  // namespace shroudsim::pipeline
