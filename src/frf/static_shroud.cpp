#include "frf/static_shroud.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/log.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "linalg/cholmod_factor.hpp"

namespace shroudsim::frf {

using linalg::SparseMatrixD;

double StaticShroud::normal_load() const {
  double n = 0.0;
  for (const auto& r : results) n += r.force[2];
  return n;
}

int StaticShroud::count(contact::StaticState s) const {
  int c = 0;
  for (const auto& r : results) c += r.state == s ? 1 : 0;
  return c;
}

namespace {

StaticShroud face_elements(const mesh::Mesh& mesh, const StaticShroudSettings& settings) {
  StaticShroud out;
  out.face = shroud_face(mesh);
  try {
    out.springs =
        face_springs(mesh, out.face, settings.normal_stiffness, settings.tangential_stiffness, settings.frame_angle);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  for (const auto& sp : out.springs) {
    contact::StaticPairParameters p;
    p.normal_stiffness = sp.stiffness[2];
    p.tangential_stiffness = sp.stiffness[0];
    p.friction_coefficient = settings.friction_coefficient;
    p.interference = settings.interference;
    out.parameters.push_back(p);
  }
  return out;
}

}  // namespace

StaticShroudSolver::StaticShroudSolver(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km,
                                       const modal::RotatingOperators* ops, const StaticShroudSettings& settings)
    : mesh_(mesh), km_(km), ops_(ops), out_(face_elements(mesh, settings)), contact_(out_.parameters) {
  if (ops_) D_ = ops_->rotating_stiffness();
  out_.results = contact_.pairs();
  out_.displacement = Eigen::VectorXd::Zero(mesh.n_dofs());
}

void StaticShroudSolver::step_to(double speed_rad_s) {
  log::Stopwatch clock;
  const double w2 = ops_ ? speed_rad_s * speed_rad_s : 0.0;
  const linalg::SparsePair<double> kmk{w2 > 0 ? SparseMatrixD(km_.K + w2 * D_) : km_.K, km_.M};
  const cyclic::CyclicSector sector(mesh_, kmk);
  const SparseMatrixD T0 = sector.expansion(0).real();
  const SparseMatrixD K0 = sector.reduce_real(0).K;
  linalg::CholmodFactor<double> factor(linalg::FactorMethod::Supernodal);
  std::ostringstream at;
  at << "at " << speed_rad_s * 60.0 / (2.0 * 3.14159265358979323846) << " rpm";
  if (factor.compute(K0) != linalg::FactorStatus::Success)
    throw NumericalError("static shroud contact " + at.str() + ": K_0 + Omega^2 D is not positive definite (" +
                         linalg::to_string(factor.status()) + ")");
  const SparseMatrixD B = SparseMatrixD(sector.interface_rows(0, out_.springs).real()) * T0;
  const Eigen::MatrixXd X = factor.solve(Eigen::MatrixXd(B.transpose()));  // n_red x 3P
  const Eigen::MatrixXd C = B * X;
  const Eigen::MatrixXd Cs = 0.5 * (C + C.transpose());
  Eigen::VectorXd u_ext = Eigen::VectorXd::Zero(K0.rows());
  if (w2 > 0) u_ext = factor.solve(Eigen::MatrixXd(T0.transpose() * (w2 * ops_->load))).col(0);
  const Eigen::VectorXd g_ext = B * u_ext;
  const contact::StaticStep st = contact_.solve(Cs, g_ext);
  out_.newton_iterations += st.newton_iterations;
  if (!st.converged) throw NumericalError("static shroud contact " + at.str() + ": " + st.message);
  out_.results = contact_.pairs();
  out_.displacement = T0 * (u_ext - X * contact_.forces());
  ++out_.increments;
  out_.seconds += clock.seconds();
}

StaticShroud solve_static_shroud(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km,
                                 const modal::RotatingOperators* ops, const StaticShroudSettings& settings) {
  StaticShroudSolver solver(mesh, km, ops, settings);
  const bool spinning = settings.speed_rad_s > 0.0 && ops != nullptr;
  const int steps = spinning ? std::max(1, settings.increments) : 1;
  for (int k = 1; k <= steps; ++k)
    solver.step_to(spinning ? settings.speed_rad_s * std::sqrt(static_cast<double>(k) / steps) : 0.0);
  return solver.state();
}

std::vector<contact::PairParameters> patch_parameters(const std::vector<ContactPatch>& patches, double face_area,
                                                      const contact::PairParameters& face, const StaticShroud* state) {
  std::vector<contact::PairParameters> out;
  for (const auto& p : patches) {
    const double s = p.area / face_area;
    contact::PairParameters pp;
    pp.friction_coefficient = face.friction_coefficient;
    pp.tangential_stiffness = face.tangential_stiffness * s;
    pp.normal_stiffness = face.normal_stiffness * s;
    pp.normal_preload = face.normal_preload * s;
    if (state) {
      pp.preload_in_equilibrium = true;
      pp.normal_preload = 0.0;
      for (int member : p.members) {
        const auto& r = state->results[static_cast<std::size_t>(member)];
        pp.normal_preload += r.state == contact::StaticState::open
                                 ? -state->parameters[static_cast<std::size_t>(member)].normal_stiffness * r.gap
                                 : r.force[2];
      }
    }
    out.push_back(pp);
  }
  return out;
}

}  // namespace shroudsim::frf
