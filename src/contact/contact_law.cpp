#include "contact/contact_law.hpp"

#include <cmath>
#include <sstream>

namespace shroudsim::contact {

std::string to_string(Model model) {
  switch (model) {
    case Model::full3d: return "full3d";
    case Model::quasi3d: return "quasi3d";
    case Model::one_d: return "1d";
    case Model::one_d_exact: return "1d_exact";
  }
  return "?";
}

std::string to_string(TangentialUpdate update) {
  return update == TangentialUpdate::radial_return ? "radial_return" : "exact_linear";
}

int n_directions(Model model) { return (model == Model::one_d || model == Model::one_d_exact) ? 1 : 3; }

int n_tangential_directions(Model model) { return n_directions(model) == 1 ? 1 : 2; }

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}

void require(bool ok, const std::string& message, std::vector<std::string>* errors, bool* valid) {
  if (!ok) {
    *valid = false;
    if (errors) errors->push_back(message);
  }
}

}  // namespace

bool PairParameters::validate(Model model, std::vector<std::string>* errors) const {
  bool valid = true;
  const double kt = tangential_stiffness, kn = normal_stiffness, mu = friction_coefficient, n0 = normal_preload;
  require(std::isfinite(kt) && kt > 0.0,
          "tangential_stiffness = " + num(kt) + " violates: tangential_stiffness > 0 (finite)", errors, &valid);
  if (n_directions(model) == 3) {
    require(std::isfinite(kn) && kn > 0.0, "normal_stiffness = " + num(kn) + " violates: normal_stiffness > 0 (finite)",
            errors, &valid);
  }
  require(std::isfinite(mu) && mu >= 0.0,
          "friction_coefficient = " + num(mu) + " violates: friction_coefficient >= 0 (finite)", errors, &valid);
  require(std::isfinite(n0), "normal_preload = " + num(n0) + " violates: finite", errors, &valid);
  if (n_directions(model) == 1) {
    require(!(n0 < 0.0),
            "normal_preload = " + num(n0) + " violates: normal_preload >= 0 for model " + to_string(model) +
                " (constant normal load, no gap)",
            errors, &valid);
  }
  return valid;
}

bool LawOptions::validate(std::vector<std::string>* errors) const {
  bool valid = true;
  require(max_periods >= 1, "max_periods = " + std::to_string(max_periods) + " violates: >= 1", errors, &valid);
  require(std::isfinite(period_tolerance) && period_tolerance > 0.0 && period_tolerance <= 1e-3,
          "period_tolerance = " + num(period_tolerance) + " violates: 0 < period_tolerance <= 1e-3", errors, &valid);
  return valid;
}

}  // namespace shroudsim::contact
