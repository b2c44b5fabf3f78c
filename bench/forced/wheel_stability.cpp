// Hill's method on an FE sector case against its whole wheel's time integration, at the size of
// the case (BENCHMARKS.md "The default sector judged"; docs/physics.md section 9, "The FE
// sector against its whole wheel"). A plain program (one timed pass is the figure wanted).
//
//   wheel_stability CASE.toml MODES SAMPLES F1 [F2 ...]
//
// The case's sector with MODES modes of every harmonic index 0..Nb/2 and without residual
// flexibility (frf::SectorLinearPart::modes_only: the wheel has the modes and nothing else), its
// harmonic balance at the case's H and N. At each frequency F [Hz] the solution of a short trace
// from F is judged twice:
//  - Hill's method over the sector's perturbation families with the slider as a state sampled at
//    SAMPLES points (forced::contact_memory);
//  - the shooting on the whole wheel in modal coordinates (forced::modal_wheel): Newton on its
//    period map from the harmonic balance's state, the law in continuous time on every sector's
//    pairs, and the Floquet multipliers of its monodromy.
// One Markdown row per frequency: the verdicts, the spectral radii, the shooting's start mismatch
// and the seconds each took.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "forced/frequency_response.hpp"
#include "forced/modal_wheel.hpp"
#include "forced/reduced_equations.hpp"
#include "forced/shooting.hpp"
#include "forced/stability.hpp"
#include "frf/sector.hpp"
#include "io/case.hpp"
#include "pipeline/context.hpp"
#include "pipeline/forced_model.hpp"

using namespace shroudsim;

namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
const char* verdict(bool available, bool stable) { return !available ? "n/a" : stable ? "stable" : "unstable"; }
}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: wheel_stability CASE.toml MODES SAMPLES F1 [F2 ...]\n");
    return 2;
  }
  try {
    pipeline::Context ctx;
    ctx.config = io::load_case(argv[1], {"modal.modes=" + std::string(argv[2]), "response.stability_method=\"hill\""});
    ctx.out_dir = "wheel_stability";
    ctx.threads = 1;
    const int samples = std::stoi(argv[3]);
    const forced::ForcedModel full = pipeline::make_sector_model(ctx);
    const auto* sector = dynamic_cast<const frf::SectorLinearPart*>(full.linear.get());
    if (sector == nullptr) throw InputError("wheel_stability: the case is not an FE sector");
    const frf::SectorLinearPart part = sector->modes_only();
    forced::ForcedModel model;
    model.linear = std::make_unique<frf::SectorLinearPart>(part);
    model.pairs = full.pairs;
    const hbm::ContactEvaluatorOptions options = pipeline::evaluator_options(ctx.config, 1);
    hbm::ContactEvaluator evaluator(options, model.pairs);
    forced::ReducedEquations equations(*model.linear, evaluator);
    const forced::ModalWheel wheel = forced::modal_wheel(part, model.pairs, equations.excitation_scale());
    std::printf(
        "%s: %s modes per index, H = %d, N = %d, slider state at %d samples; the wheel: %ld coordinates, %zu "
        "contact elements\n\n",
        argv[1], argv[2], options.n_harmonics, options.n_time_samples, samples,
        static_cast<long>(wheel.system.mass.rows()), wheel.pairs.size());
    std::printf("| frequency [Hz] | Hill | radius | pencil | s | wheel | radius | start mismatch | s |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (int i = 4; i < argc; ++i) {
      forced::FrequencyResponseSettings settings = pipeline::frequency_response_settings(ctx.config);
      settings.frequency_start_hz = std::stod(argv[i]);
      settings.frequency_end_hz = settings.frequency_start_hz + 0.2;
      settings.initial_step_hz = 0.1;
      settings.locate_peaks = false;
      const forced::FrequencyResponse r = forced::trace_frequency_response(settings, model, options, equations);
      if (r.points.empty()) {
        std::printf("| %s | no solution | | | | | | | |\n", argv[i]);
        continue;
      }
      const continuation::BranchPoint& p = r.points.front();
      auto start = std::chrono::steady_clock::now();
      const forced::ContactMemory memory = forced::contact_memory(equations, p.x, samples);
      const forced::FloquetResult hill =
          forced::floquet_exponents(equations, p.x, p.lambda, forced::ExponentSelection::symmetry,
                                    forced::kMaxSliderStateSize, forced::kModeCutoff, &memory);
      const double hill_seconds = seconds_since(start);
      start = std::chrono::steady_clock::now();
      Eigen::VectorXd u0, v0, d0;
      forced::modal_wheel_state(wheel, part, equations, options.law.model, p.x, p.lambda, u0, v0, d0);
      forced::ShootingOptions so;
      so.max_newton_iterations = 30;  // the harmonic balance's state is a truncation away from the orbit
      const forced::ShootingResult sh =
          forced::shooting_floquet(wheel.system, wheel.pairs, options.law.model, p.lambda, u0, v0, d0, so);
      std::printf("| %.3f | %s | %.4f | %d | %.1f | %s | %.4f | %.2e | %.0f |\n", p.lambda,
                  verdict(hill.available, hill.stable), hill.spectral_radius(p.lambda), hill.hill_size, hill_seconds,
                  verdict(sh.available && !sh.multipliers.empty(), sh.stable), sh.spectral_radius, sh.start_mismatch,
                  seconds_since(start));
      if (!hill.available) std::printf("\nHill at %.3f Hz: %s\n\n", p.lambda, hill.reason.c_str());
      if (!sh.available) std::printf("\nthe wheel at %.3f Hz: %s\n\n", p.lambda, sh.reason.c_str());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wheel_stability: %s\n", e.what());
    return 2;
  }
  return 0;
}
