#pragma once
// The forced-response models the frf command builds from a case.
#include <memory>
#include <vector>

#include "app/context.hpp"
#include "contact/contact_law.hpp"
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

}  // namespace shroudsim::app
