// `shroudsim contact CASE`: one contact pair under the periodic relative motion of [motion]
// -> contact.json (force harmonics, time histories / hysteresis loops, Jacobian, timings).
// The discrete contact map depends on the phase only, so the motion is evaluated at the
// normalised circular frequency w = 2 pi rad/s (period 1 s); contact.json says so.
#include <cmath>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "app/context.hpp"
#include "contact/contact_law.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "hbm/contact_evaluator.hpp"
#include "io/output.hpp"

namespace shroudsim::app {
namespace {

constexpr double kPi = std::numbers::pi;
// Timing: repeat an evaluation until this much wall time has passed (or kMaxRepeats).
constexpr double kTimingSeconds = 0.05;
constexpr int kMaxRepeats = 1000;

[[noreturn]] void refuse(const io::Case& c, const std::string& key, const std::string& what) {
  throw InputError(c.where(key) + ": " + key + " " + what);
}

template <class F>
double seconds_per_call(F&& f) {
  log::Stopwatch clock;
  int calls = 0;
  do {
    f();
    ++calls;
  } while (clock.seconds() < kTimingSeconds && calls < kMaxRepeats);
  return clock.seconds() / calls;
}

nlohmann::json harmonics_json(const hbm::HarmonicLayout& layout, const Eigen::VectorXd& v, int dir) {
  nlohmann::json rows = nlohmann::json::array();
  const int m = layout.per_direction();
  rows.push_back({0, v[dir * m], 0.0});
  for (int n = 1; n <= layout.n_harmonics(); ++n) rows.push_back({n, v[dir * m + 2 * n - 1], v[dir * m + 2 * n]});
  return rows;
}

std::string sci(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}

std::vector<double> column(const Eigen::MatrixX3d& m, int c) {
  return std::vector<double>(m.col(c).data(), m.col(c).data() + m.rows());
}

}  // namespace

int cmd_contact(Context& ctx) {
  const io::Case& c = ctx.config;
  log::Stopwatch total;

  // --- options ---------------------------------------------------------------------------
  const contact::Model model = c.contact.model;
  const contact::TangentialUpdate update = c.contact.tangential_update;
  const hbm::JacobianMethod method = c.hbm.jacobian;
  if (c.hbm.harmonics_auto || c.hbm.time_samples_auto)
    refuse(c, "hbm.harmonics", "= \"auto\" violates: explicit harmonics and time_samples for `shroudsim contact`");
  const int h = c.hbm.harmonics;
  const int n = c.hbm.time_samples;
  if (model == contact::Model::one_d_exact && h != 1)
    refuse(c, "hbm.harmonics",
           "= " + std::to_string(h) +
               " violates: harmonics = 1 for contact.model = \"1d_exact\" "
               "(the time-continuous single-harmonic law)");

  contact::PairParameters pair;
  pair.tangential_stiffness = c.contact.tangential_stiffness;
  pair.normal_stiffness = c.contact.normal_stiffness;
  pair.friction_coefficient = c.contact.friction_coefficient;
  pair.normal_preload = c.contact.normal_preload;
  {
    std::vector<std::string> errors;
    if (!pair.validate(model, &errors)) {
      const std::string key = "contact." + errors.front().substr(0, errors.front().find(' '));
      throw InputError(c.where(key) + ": contact." + errors.front());
    }
  }

  hbm::ContactEvaluatorOptions options;
  options.n_harmonics = h;
  options.n_time_samples = n;
  options.law.model = model;
  options.law.update = update;
  options.jacobian = method;
  options.threads = 1;
  {
    std::vector<std::string> errors;
    if (!options.validate(&errors)) throw InputError(c.file.string() + ": hbm." + errors.front());
  }

  // --- motion -> W (pair layout), in the pair frame turned by frame_angle_deg -------------
  hbm::ContactEvaluator evaluator(options, {pair});
  const hbm::HarmonicLayout& layout = evaluator.pair_layout();
  const int m = layout.per_direction();
  const int dirs = layout.n_directions();
  Eigen::VectorXd w_in = Eigen::VectorXd::Zero(3 * m);  // x, y, z as given
  const std::vector<io::MotionHarmonic>* motion[3] = {&c.motion.x, &c.motion.y, &c.motion.z};
  const char* names[3] = {"motion.x", "motion.y", "motion.z"};
  for (int d = 0; d < 3; ++d) {
    for (const auto& row : *motion[d]) {
      if (!std::isfinite(row.cosine) || !std::isfinite(row.sine))
        refuse(c, names[d], "row for harmonic " + std::to_string(row.harmonic) + " violates: finite amplitudes");
      if (row.harmonic < 0 || row.harmonic > h)
        refuse(c, names[d],
               "harmonic " + std::to_string(row.harmonic) +
                   " violates: 0 <= harmonic <= hbm.harmonics (= " + std::to_string(h) + ")");
      if (row.harmonic == 0 && row.sine != 0.0)
        refuse(c, names[d],
               "harmonic 0 sine = " + std::to_string(row.sine) + " violates: 0 (the mean has no sine part)");
      w_in[d * m + hbm::HarmonicLayout::local_index(row.harmonic, hbm::HarmonicLayout::Part::cosine)] += row.cosine;
      if (row.harmonic > 0)
        w_in[d * m + hbm::HarmonicLayout::local_index(row.harmonic, hbm::HarmonicLayout::Part::sine)] += row.sine;
    }
  }
  if (dirs == 1 && (w_in.segment(m, 2 * m).array() != 0.0).any())
    ctx.report.warn("contact: motion.y and motion.z are ignored by contact.model = \"" + contact::to_string(model) +
                    "\" (x only, constant normal load)");
  const double psi = c.contact.frame_angle_deg * kPi / 180.0;
  if (!std::isfinite(psi)) refuse(c, "contact.frame_angle_deg", "violates: finite");
  Eigen::VectorXd w(layout.size());
  if (dirs == 3) {
    // Local axes t1, t2 turned by psi about n: x' = cos x + sin y, y' = -sin x + cos y.
    w.segment(0, m) = std::cos(psi) * w_in.segment(0, m) + std::sin(psi) * w_in.segment(m, m);
    w.segment(m, m) = -std::sin(psi) * w_in.segment(0, m) + std::cos(psi) * w_in.segment(m, m);
    w.segment(2 * m, m) = w_in.segment(2 * m, m);
  } else {
    w = w_in.segment(0, m);
  }

  // --- evaluate ----------------------------------------------------------------------------
  hbm::PairDetail detail;
  evaluator.evaluate_pair(0, w, detail, true);
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> jac;
  const double t_residual = seconds_per_call([&] { evaluator.evaluate(w, f, nullptr); });
  const double t_jacobian = seconds_per_call([&] { evaluator.evaluate(w, f, &jac); });
  const hbm::JacobianMethod other = method == hbm::JacobianMethod::analytic ? hbm::JacobianMethod::finite_difference
                                                                            : hbm::JacobianMethod::analytic;
  std::vector<Eigen::MatrixXd> jac_other;
  const double t_other = seconds_per_call([&] { evaluator.evaluate(w, f, &jac_other, other); });
  const double jac_difference =
      (detail.jacobian - jac_other[0]).norm() / std::max(jac_other[0].norm(), std::numeric_limits<double>::min());
  const double energy = hbm::dissipated_energy(layout, w, detail.force);

  if (!detail.force.allFinite() || !detail.jacobian.allFinite() || !detail.f.allFinite() || !std::isfinite(energy))
    throw NumericalError("contact: the evaluation produced a non-finite value");
  if (!detail.status.converged)
    ctx.report.warn("contact: the damper state did not repeat within " + std::to_string(options.law.max_periods) +
                    " periods; the last period is reported (converged_periodic = false)");

  // --- contact.json ------------------------------------------------------------------------
  nlohmann::json j;
  j["model"] = contact::to_string(model);
  j["tangential_update"] = contact::to_string(update);
  j["jacobian_method"] = hbm::to_string(method);
  j["harmonics"] = h;
  j["time_samples"] = model == contact::Model::one_d_exact ? static_cast<int>(detail.w.rows()) : n;
  j["omega_rad_s"] = 2.0 * kPi;
  j["omega_note"] = "the discrete contact map depends only on the phase: evaluated at w = 2 pi rad/s (period 1 s)";
  j["frame"] = "pair frame (t1, t2, n) turned by contact.frame_angle_deg; x, y tangential, z normal (> 0 presses)";
  j["pair"] = {{"tangential_stiffness_n_m", pair.tangential_stiffness},
               {"normal_stiffness_n_m", pair.normal_stiffness},
               {"friction_coefficient", pair.friction_coefficient},
               {"normal_preload_n", pair.normal_preload}};
  j["converged_periodic"] = detail.status.converged;
  j["periods"] = detail.status.periods;
  j["dissipated_energy_j"] = energy;
  const char* dn[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d) {
    j["motion_harmonics"][dn[d]] = d < dirs ? harmonics_json(layout, w, d) : nlohmann::json::array();
    j["force_harmonics"][dn[d]] = d < dirs ? harmonics_json(layout, detail.force, d) : nlohmann::json::array();
  }
  std::vector<double> t(static_cast<size_t>(detail.w.rows()));
  for (size_t l = 0; l < t.size(); ++l) t[l] = static_cast<double>(l) / static_cast<double>(t.size());
  Eigen::MatrixX3d fh = detail.f;
  if (dirs == 1) fh.col(2).setConstant(pair.normal_preload);  // 1d: constant normal load
  j["time"] = {{"t_s", t},
               {"x", column(detail.w, 0)},
               {"y", column(detail.w, 1)},
               {"z", column(detail.w, 2)},
               {"tx", column(fh, 0)},
               {"ty", column(fh, 1)},
               {"n", column(fh, 2)}};
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < detail.jacobian.rows(); ++r) {
    std::vector<double> row(static_cast<size_t>(detail.jacobian.cols()));
    for (Eigen::Index k = 0; k < detail.jacobian.cols(); ++k) row[static_cast<size_t>(k)] = detail.jacobian(r, k);
    rows.push_back(row);
  }
  j["jacobian"] = rows;
  j["jacobian_layout"] = std::string("dF/dW in N/m; rows and columns: ") + (dirs == 3 ? "[x | y | z]" : "[x]") +
                         " blocks, each [c0, c1, s1, ..., cH, sH]";
  j["jacobian_relative_difference_to_" + hbm::to_string(other)] = jac_difference;
  j["seconds"] = {{"residual", t_residual},
                  {"jacobian", t_jacobian},
                  {"jacobian_" + hbm::to_string(other), t_other},
                  {"total", total.seconds()}};
  io::write_file_atomic(ctx.out_dir / "contact.json", j.dump(1) + "\n");

  ctx.report.section("contact") = {{"model", contact::to_string(model)},
                                   {"converged_periodic", detail.status.converged},
                                   {"periods", detail.status.periods},
                                   {"dissipated_energy_j", energy}};
  ctx.report.stage("contact", total.seconds());
  log::info("contact: " + contact::to_string(model) + "/" + contact::to_string(update) + ", H = " + std::to_string(h) +
            ", N = " + std::to_string(n) + ", " + std::to_string(detail.status.periods) + " periods" +
            (detail.status.converged ? "" : " (not converged)") + ", dissipated " + sci(energy) + " J/cycle -> " +
            (ctx.out_dir / "contact.json").string());
  draw_plots(ctx);
  return 0;
}

}  // namespace shroudsim::app
