#pragma once
// The forced-response models the frf command builds from a case.
#include <memory>
#include <string>
#include <vector>

#include "app/context.hpp"
#include "continuation/arclength.hpp"
#include "contact/contact_law.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/linear_part.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::app {

/// A linear part and the parameters of its contact pairs, in the same order.
struct ForcedModel {
  std::unique_ptr<frf::LinearPart> linear;
  std::vector<contact::PairParameters> pairs;
};

/// structure.type = "lumped": M, K, C and [[contact.elements]].
ForcedModel make_lumped_model(const io::Case& c);
/// structure.type = "sector": modal receptances of the sector, shroud contact pairs.
ForcedModel make_sector_model(Context& ctx);
/// The contact evaluator options of a case (H, N, model, update, Jacobian kind).
hbm::ContactEvaluatorOptions evaluator_options(const io::Case& c, int threads);
/// The continuation options of a case's forced response: the [continuation] range and step,
/// W scaled by 1/20 of the largest free contact motion over the range (the contact's own
/// scale, mu |N0| / kt or |N0| / kn, when nothing moves), at least ~200 points over the range.
continuation::ArclengthOptions arclength_options(const io::Case& c, const ForcedModel& model,
                                                 const forced::ReducedEquations& equations);
/// A solution of `equations` at frequency f: Newton from the stuck-contact solution; where it
/// fails (Newton cycling between contact states), from the free response, then harmonic
/// stepping (H = 1, then one harmonic at a time, each new one from zero), then continuation in
/// the excitation level from the preload-only state. When all of these fail at f, the same
/// search a little way off (f (1 +- 0.002, 0.005, 0.01)), then Newton at fixed frequencies
/// back to f. `how` names the method that worked. Throws NumericalError when none does.
Eigen::VectorXd find_start(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                           forced::ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                           std::string& how);

}  // namespace shroudsim::app
