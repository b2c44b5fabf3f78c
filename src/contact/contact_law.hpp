#pragma once
// The time-discrete friction contact law of one node-to-node pair (docs/physics.md section 4):
// the models, the tangential update, the pair's parameters and the law's options, each with
// its validation. The law itself is built of:
//   contact/friction_step.hpp      the update of one time sample (the laws proper);
//   contact/periodic_law.hpp       the periodic steady state over a period (PeriodicLaw);
//   contact/linearized_period.hpp  its exact derivative (section 5) in compact form.
//
// Relative displacement samples w(l) = (x, y, z)(l), l = 0..N-1, over one period [m]:
// x, y tangential, z normal (z > 0 presses). Forces F(l) = (Tx, Ty, N)(l) [N]:
//   N(l) = max(0, N0 + kn z(l))                    (1d: N = N0, constant)
//   damper position d (tangential, [m]), T = kt (w_t - d), |T| <= mu N.
// Tangential update of the coupled law (full3d): radial_return takes the trial force
// T* = kt (w_t(l) - d(l-1)) and returns it radially onto |T| <= mu N(l) (first order on 2D
// orbits); exact_linear takes w_t and the slip radius mu N/kt linear within each step and
// integrates the stick/slip evolution exactly (second order; see exact_linear_step), and in a
// step where the contact closes starts the slider at the closing instant (second order
// through separation). For the 1D laws (quasi3d per axis, 1d) both are the exact clamp and
// coincide, except in such a closing step.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace shroudsim::contact {

/// Contact model (docs/contract.md [contact] model).
enum class Model {
  full3d,      ///< coupled 2D tangential Coulomb, variable normal load, separation
  quasi3d,     ///< x and y as two independent 1D laws, each with limit mu N(l)
  one_d,       ///< x only, constant normal load N0 ("1d")
  one_d_exact  ///< "1d_exact": time-continuous single-harmonic Jenkins solution (H = 1)
};

/// Tangential update of the coupled law (docs/physics.md section 4).
enum class TangentialUpdate {
  radial_return,  ///< trial force, radial return to the circle mu N (the paper's; 1st order in 2D)
  exact_linear    ///< w_t linear within a step, integrated exactly (2nd order in 2D)
};

std::string to_string(Model model);              ///< "full3d", "quasi3d", "1d", "1d_exact" (contact.model)
std::string to_string(TangentialUpdate update);  ///< "radial_return", "exact_linear" (contact.tangential_update)

/// Directions a model uses: 3 (x, y, z) or 1 (x) for the 1d models.
int n_directions(Model model);
/// Tangential directions of a model's friction slider: 1 for the 1d models, 2 otherwise.
int n_tangential_directions(Model model);

/// Physical parameters of one pair. SI units.
struct PairParameters {
  double tangential_stiffness = 1.0e6;  ///< kt [N/m], > 0
  double normal_stiffness = 1.0e6;      ///< kn [N/m], > 0 (not used by the 1d models)
  double friction_coefficient = 0.3;    ///< mu [-], >= 0
  double normal_preload = 0.25;         ///< N0 [N]; < 0: initial gap -N0/kn (1d models: >= 0)
  /// N0 is the normal load of a static equilibrium the linear model is written about
  /// (contact.normal_preload = "static"): the structure already carries max(0, N0), so the
  /// forced response's static harmonic balances only the change of the contact force from it
  /// (docs/physics.md sections 3 and 8). false: N0 acts on the structure at zero relative
  /// displacement, and the static harmonic balances it (the paper's preload).
  bool preload_in_equilibrium = false;

  /// Appends one message per violated constraint ("key = value violates: ...", keys as in
  /// docs/contract.md [contact]); returns true when valid.
  bool validate(Model model, std::vector<std::string>* errors) const;
};

/// Options of the time-domain law.
struct LawOptions {
  Model model = Model::full3d;
  TangentialUpdate update = TangentialUpdate::exact_linear;
  int max_periods = 200;            ///< cap on repeated periods, >= 1
  double period_tolerance = 1e-12;  ///< relative repeat tolerance of d, in (0, 1e-3]

  bool validate(std::vector<std::string>* errors) const;
};

}  // namespace shroudsim::contact
