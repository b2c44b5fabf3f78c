// Forced response of a case with the cost split by where it goes, and (--jacobian-check)
// the Jacobian error against central differences along the solution curve (the paper's
// Figure 17). A plain program (one timed pass is the figure wanted).
//
//   forced_pairs CASE.toml [--set KEY=VALUE]... [--threads N] [--solver dense|krylov|auto]
//                [--jacobian-check]
//
// It builds the model as `shroudsim frf` does (make_sector_model / make_lumped_model, the same
// variable scaling and continuation options), starts from the stuck-contact state (or the
// excitation homotopy) and traces the branch over the case's range, then prints one line of
// `key=value` pairs: points, seconds (trace only), contact/receptance/jacobian/solve seconds,
// Newton iterations, factorizations, GMRES solves and iterations.
//
// --jacobian-check: at every converged point both contact Jacobians are evaluated
// (ContactEvaluator::evaluate with JacobianMethod::analytic and ::finite_difference) and
//   e_contact = ||D_a - D_fd||_F / ||D_a||_F       (all pairs' blocks stacked)
//   e_full    = ||G (D_a - D_fd)||_F / ||I + G D_a||_F   (the reduced Jacobian)
// are recorded; their maximum and median over the curve and the frequency of the maximum are
// printed (timings then include the checks).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "continuation/arclength.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "forced/reduced_equations.hpp"
#include "io/case.hpp"
#include "pipeline/context.hpp"
#include "pipeline/forced_model.hpp"

using namespace shroudsim;

int main(int argc, char** argv) {
  std::vector<std::string> sets;
  std::string case_file, solver = "auto";
  int threads = 0;
  bool check = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--set" && i + 1 < argc) sets.push_back(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (a == "--solver" && i + 1 < argc) solver = argv[++i];
    else if (a == "--jacobian-check") check = true;
    else if (case_file.empty() && a.rfind("--", 0) != 0) case_file = a;
    else {
      std::cerr
          << "usage: forced_pairs CASE.toml [--set KEY=VALUE]... [--threads N] [--solver dense|krylov|auto] [--jacobian-check]\n";
      return 2;
    }
  }
  if (case_file.empty()) {
    std::cerr << "usage: forced_pairs CASE.toml [--set KEY=VALUE]...\n";
    return 2;
  }
  try {
    log::set_verbose(false);
    pipeline::Context ctx;
    ctx.config = io::load_case(case_file, sets);
    ctx.threads = threads;
    ctx.plots = false;
    ctx.out_dir = "/tmp";
    const io::Case& c = ctx.config;
    pipeline::ForcedModel model = c.structure.type == io::StructureType::lumped ? pipeline::make_lumped_model(c)
                                                                                : pipeline::make_sector_model(ctx);
    const hbm::ContactEvaluatorOptions eo = pipeline::evaluator_options(c, threads);
    hbm::ContactEvaluator evaluator(eo, model.pairs);
    forced::ReducedEquations equations(*model.linear, evaluator);
    forced::LinearSolverOptions so;
    so.kind = solver == "dense"    ? forced::LinearSolverOptions::Kind::dense
              : solver == "krylov" ? forced::LinearSolverOptions::Kind::krylov
                                   : forced::LinearSolverOptions::Kind::automatic;
    equations.set_linear_solver(so);

    // The units, options and start of the frequency response (forced/frequency_response.hpp).
    const continuation::ArclengthOptions ao =
        forced::arclength_options(pipeline::frequency_response_settings(c), model, equations);

    log::Stopwatch clock;
    std::string how;
    const Eigen::VectorXd start = forced::find_start(model, eo, equations, ao, ao.lambda_start, how);
    std::replace(how.begin(), how.end(), ' ', '_');  // one key=value token in the output
    const double start_seconds = clock.seconds();

    std::vector<double> e_contact, e_full, at;
    double check_seconds = 0.0;
    std::vector<Eigen::MatrixXd> da, dfd;
    Eigen::VectorXd fa, ffd;
    auto on_point = [&](const continuation::BranchPoint& p) {
      if (!check) return;
      log::Stopwatch cc;
      evaluator.evaluate(p.x, fa, &da, hbm::JacobianMethod::analytic);
      evaluator.evaluate(p.x, ffd, &dfd, hbm::JacobianMethod::finite_difference);
      double num = 0.0, den = 0.0;
      std::vector<Eigen::MatrixXd> diff(da.size());
      for (std::size_t k = 0; k < da.size(); ++k) {
        diff[k] = da[k] - dfd[k];
        num += diff[k].squaredNorm();
        den += da[k].squaredNorm();
      }
      e_contact.push_back(den > 0 ? std::sqrt(num / den) : std::sqrt(num));
      // G (D_a - D_fd) = (I + G (D_a - D_fd)) - I with the structured product.
      Eigen::MatrixXd ja, jd;
      equations.jacobian(p.lambda, da, ja);
      equations.jacobian(p.lambda, diff, jd);
      jd.diagonal().array() -= 1.0;
      e_full.push_back(jd.norm() / ja.norm());
      at.push_back(p.lambda);
      check_seconds += cc.seconds();
    };
    const continuation::Branch b = continuation::trace(equations, start, ao, on_point);
    const double seconds = clock.seconds();
    const forced::SolverStatistics& s = equations.statistics();
    std::cout << std::setprecision(4) << "pairs=" << evaluator.n_pairs() << " unknowns=" << equations.size()
              << " jacobian=" << hbm::to_string(c.hbm.jacobian) << " N=" << c.hbm.time_samples
              << " preload=" << c.contact.normal_preload << " solver=" << solver
              << " status=" << continuation::to_string(b.status) << " points=" << b.points.size() << " start=" << how
              << " seconds=" << seconds - check_seconds << " start_seconds=" << start_seconds
              << " newton=" << b.newton_iterations << " evaluations=" << s.evaluations
              << " jacobian_evaluations=" << s.jacobian_evaluations << " repeated=" << s.repeated_evaluations
              << " contact_s=" << s.contact_seconds << " receptance_s=" << s.receptance_seconds
              << " jacobian_s=" << s.jacobian_seconds << " solve_s=" << s.solve_seconds
              << " factorizations=" << s.dense_factorizations << " krylov_solves=" << s.krylov_solves
              << " krylov_iterations=" << s.krylov_iterations << " krylov_failures=" << s.krylov_failures;
    // Cost of one contact evaluation of all pairs at the last point (median of 7): residual
    // only, with the analytic Jacobian, with the block finite-difference Jacobian (2 residuals
    // per coefficient of each pair: what hbm.jacobian = "finite_difference" does), and what a
    // finite difference of the whole residual vector would cost (2 n residual evaluations of
    // all pairs: no use of the block-diagonal structure).
    if (!b.points.empty()) {
      const Eigen::VectorXd& x = b.points.back().x;
      auto median_ms = [&](auto&& fn) {
        std::vector<double> t;
        for (int k = 0; k < 7; ++k) {
          log::Stopwatch sw;
          fn();
          t.push_back(1e3 * sw.seconds());
        }
        std::nth_element(t.begin(), t.begin() + 3, t.end());
        return t[3];
      };
      Eigen::VectorXd fx;
      std::vector<Eigen::MatrixXd> jx;
      const double res_ms = median_ms([&] { evaluator.evaluate(x, fx, nullptr); });
      const double an_ms = median_ms([&] { evaluator.evaluate(x, fx, &jx, hbm::JacobianMethod::analytic); });
      const double fd_ms = median_ms([&] { evaluator.evaluate(x, fx, &jx, hbm::JacobianMethod::finite_difference); });
      std::cout << " residual_ms=" << res_ms << " analytic_ms=" << an_ms << " fd_block_ms=" << fd_ms
                << " fd_whole_ms=" << 2.0 * equations.size() * res_ms;
    }
    if (check && !e_contact.empty()) {
      auto stats = [&](std::vector<double> v, const char* name) {
        const auto imax = std::max_element(v.begin(), v.end()) - v.begin();
        const double mx = v[static_cast<std::size_t>(imax)];
        const double f_at = at[static_cast<std::size_t>(imax)];
        const auto above = std::count_if(v.begin(), v.end(), [](double e) { return e > 1e-6; });
        std::cout << " " << name << "_points_above_1e-6=" << above;
        std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
        std::cout << " " << name << "_max=" << mx << " " << name << "_median=" << v[v.size() / 2] << " " << name
                  << "_max_at_hz=" << f_at;
      };
      stats(e_contact, "e_contact");
      stats(e_full, "e_full");
      std::cout << " check_seconds=" << check_seconds;
    }
    std::cout << "\n";
    return b.status == continuation::BranchStatus::kReachedEnd ? 0 : 3;
  } catch (const InputError& e) {
    std::cerr << "forced_pairs: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "forced_pairs: " << e.what() << "\n";
    return 1;
  }
}
