#include "forced/frequency_response.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

#include "continuation/events.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/log.hpp"
#include "forced/excitation_homotopy.hpp"
#include "forced/time_march.hpp"
#include "frf/lumped.hpp"
#include "linalg/parallel.hpp"

namespace shroudsim::forced {
namespace {

using Info = std::function<void(const std::string&)>;

// Scaled distance (a range spans 100 units, a free peak 20) within which the second piece's
// end lies on the first piece: far below a step (>= 1e-6 * 0.25 units) and far above the
// corrector's tolerance (1e-8 on the scaled residual).
constexpr double kJoinTolerance = 1e-5;

// Points whose energy balance misses by more than this are polished (see below): Newton at
// fixed frequency with the unknowns scaled by the point's own largest contact motion, to a
// tolerance near round-off.
constexpr double kPolishAbove = 1e-6;
constexpr double kPolishTolerance = 1e-12;

// The corrector's tolerance at the trial points of a peak search, relative to the sampled
// peak's own largest unknown (never looser than the tracing tolerance). Near a maximum
// A(s) = A* - c (s - s*)^2, amplitude noise e moves the located s* by sqrt(e / c): at the
// tracing tolerance (1e-8 of the free motion, which can be 100 times the friction-damped
// peak) that reached 1e-5 of the frequency. 1e-10 keeps it near 1e-7 on the coarse sector
// (docs/continuation.md); 1e-12 costs the default wheel's peak 6 times the evaluations
// (Newton stalls near round-off) for a change of 2e-8 in its frequency.
constexpr double kPeakTolerance = 1e-10;

// The top of a resonance peak of a sampled friction law is rippled: each corner of the law
// (a sample changing between stick, slip and separation) is a kink of the amplitude along the
// branch, and near the top several kinks are local maxima of nearly the same height
// (measured on the coarse sector at N = 512: five within 3e-6 of the amplitude and 5e-5 of the
// frequency, kinks 3e-7 to 3e-6 of the frequency apart). Brent's method finds one of them,
// which one depends on the path. The largest is found by sampling the top: where the smooth
// envelope (a parabola through the three sampled points) is within kRippleBand of the located
// maximum, at kTopSamples points, then Brent's method at the kTopCandidates largest sampled
// local maxima. Where the samples show a ripple above half the band, the band is widened to
// twice it, once; the wider band samples only what the narrower one left out. The samples
// are corrected at the tracing tolerance (they only pick the candidates; Brent's method at the
// candidates uses the tight one): on the paper's preload study that took the peak location
// from 87 to 49 s, the largest peaks the same to 1e-10; sampling only the new part of a wider
// band and warm-starting Brent's trials from the best one so far, from 46 to 31 s
// (docs/continuation.md, "Peaks").
constexpr double kRippleBand = 1e-5;  // relative to the peak amplitude
constexpr int kTopSamples = 100;
constexpr int kTopCandidates = 3;

using Amplitude = std::function<double(const Eigen::VectorXd&, double)>;

// Keeps the larger of best and e.
void keep_larger(continuation::Extremum& best, const continuation::Extremum& e) {
  if (e.found && (!best.found || e.value > best.value)) best = e;
}

// The largest maximum of the amplitude on the top of the peak whose two steps run from
// pts[0] to pts[1] and from pts[1] to pts[2] (amplitudes `amp`), with `best` Brent's maximum
// on them and `lengths` the two steps' arclengths (<= 0: no step). Returns the larger of
// `best` and what the samples find; adds the residual evaluations to `evaluations`.
continuation::Extremum search_rippled_top(ReducedEquations& equations, const continuation::ArclengthOptions& fine,
                                          const continuation::ArclengthOptions& scan,
                                          const std::array<const continuation::BranchPoint*, 3>& pts,
                                          const std::array<double, 3>& amp, const std::array<double, 2>& lengths,
                                          continuation::Extremum best, const Amplitude& amplitude, int& evaluations) {
  // The envelope A(l) = c0 + c1 l + c2 l^2 through the three sampled points (l: frequency).
  const double l0 = pts[0]->lambda, l1 = pts[1]->lambda, l2 = pts[2]->lambda;
  if (!(l0 < l1 && l1 < l2) && !(l0 > l1 && l1 > l2)) return best;  // a fold beside the top
  const double d01 = (amp[1] - amp[0]) / (l1 - l0), d12 = (amp[2] - amp[1]) / (l2 - l1);
  const double c2 = (d12 - d01) / (l2 - l0);
  if (!(c2 < 0) || !best.found) return best;
  double band = kRippleBand;
  struct Sample {
    continuation::Extremum e;
    int step;
    bool refined = false;  // Brent's method has run at it
  };
  std::vector<Sample> samples;  // every pass's, ordered by step, then by s
  // The s already sampled, per step (empty: lower end above the upper).
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::array<double, 2> a_done{kInf, kInf}, b_done{-kInf, -kInf};
  for (int pass = 0; pass < 2; ++pass) {
    const double half_width = std::sqrt(band * best.value / -c2);
    const double lo = best.lambda - half_width, hi = best.lambda + half_width;
    const double spacing = (hi - lo) / kTopSamples;
    for (int k = 0; k < 2; ++k) {
      if (!(lengths[k] > 0)) continue;
      // s along step k, linear in frequency between its ends (which may run downwards).
      const double la = pts[k]->lambda, lb = pts[k + 1]->lambda;
      const double s_at_lo = std::clamp(lengths[k] * (lo - la) / (lb - la), 0.0, lengths[k]);
      const double s_at_hi = std::clamp(lengths[k] * (hi - la) / (lb - la), 0.0, lengths[k]);
      const double a = std::min(s_at_lo, s_at_hi), b = std::max(s_at_lo, s_at_hi);
      const int n = static_cast<int>(std::ceil((b - a) / (lengths[k] * spacing / std::abs(lb - la))));
      if (n < 1) continue;
      // A wider band samples only what the narrower one did not (there it was finer).
      std::vector<double> below, above;
      for (int j = 0; j <= n; ++j) {
        const double sj = a + (b - a) * j / n;
        if (sj < a_done[k]) below.push_back(sj);
        else if (sj > b_done[k]) above.push_back(sj);
      }
      a_done[k] = std::min(a, a_done[k]);
      b_done[k] = std::max(b, b_done[k]);
      for (const std::vector<double>* part : {&below, &above}) {
        if (part->empty()) continue;
        for (continuation::Extremum& e : continuation::sample_along(equations, scan, *pts[k], *part, amplitude)) {
          evaluations += e.evaluations;
          samples.push_back({std::move(e), k});
        }
      }
    }
    std::stable_sort(samples.begin(), samples.end(), [](const Sample& p, const Sample& q) {
      return p.step != q.step ? p.step < q.step : p.e.s < q.e.s;
    });
    // The ripple: the largest departure of the found samples from their own least-squares
    // parabola in the frequency (centred and scaled to the band).
    const auto n_found = std::count_if(samples.begin(), samples.end(), [](const Sample& q) { return q.e.found; });
    Eigen::MatrixXd v(n_found, 3);
    Eigen::VectorXd rhs(n_found);
    Eigen::Index row = 0;
    for (const Sample& q : samples) {
      if (!q.e.found) continue;
      const double t = (q.e.lambda - best.lambda) / (hi - lo);
      v.row(row) << 1.0, t, t * t;
      rhs[row++] = q.e.value;
    }
    // Brent's method at the largest sampled local maxima (neighbours on the same step) that
    // it has not run at yet.
    std::vector<std::size_t> candidates;
    for (std::size_t j = 1; j + 1 < samples.size(); ++j) {
      const Sample &p = samples[j - 1], &q = samples[j], &r = samples[j + 1];
      if (p.step != q.step || r.step != q.step || !p.e.found || !q.e.found || !r.e.found) continue;
      if (q.e.value >= p.e.value && q.e.value >= r.e.value) candidates.push_back(j);
    }
    std::sort(candidates.begin(), candidates.end(),
              [&](std::size_t a, std::size_t b) { return samples[a].e.value > samples[b].e.value; });
    if (candidates.size() > static_cast<std::size_t>(kTopCandidates)) candidates.resize(kTopCandidates);
    for (std::size_t j : candidates) {
      if (samples[j].refined) continue;
      samples[j].refined = true;
      const int k = samples[j].step;
      const continuation::Extremum e = continuation::locate_maximum(equations, fine, *pts[k], samples[j - 1].e.s,
                                                                    samples[j + 1].e.s, amplitude, 1e-7, &samples[j].e);
      evaluations += e.evaluations;
      // The sample itself (at the tracing tolerance) counts only where Brent's method fails.
      keep_larger(best, e.found ? e : samples[j].e);
    }
    if (v.rows() < 4) break;
    const Eigen::VectorXd coef = v.colPivHouseholderQr().solve(rhs);
    const double ripple = (v * coef - rhs).lpNorm<Eigen::Infinity>() / best.value;
    if (!(2 * ripple > band)) break;
    band = 2 * ripple;
  }
  return best;
}

void say(const Info& info, const std::string& s) {
  if (info) info(s);
}

// `v`, a solution with `from_h` harmonics, in the layout of `to` (more harmonics): the new
// harmonics zero.
Eigen::VectorXd with_more_harmonics(const Eigen::VectorXd& v, int from_h, const hbm::ContactEvaluator& to) {
  const auto& lo = to.pair_layout();
  const hbm::HarmonicLayout from(from_h, lo.n_directions());
  Eigen::VectorXd w = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(to.n_pairs()) * lo.size());
  for (int p = 0; p < to.n_pairs(); ++p)
    for (int d = 0; d < lo.n_directions(); ++d)
      for (int n = 0; n <= from_h; ++n)
        for (auto part : {hbm::HarmonicLayout::Part::cosine, hbm::HarmonicLayout::Part::sine}) {
          if (n == 0 && part == hbm::HarmonicLayout::Part::sine) continue;
          w[p * lo.size() + lo.index(d, n, part)] = v[p * from.size() + from.index(d, n, part)];
        }
  return w;
}

}  // namespace

int last_serving_point(int last, const std::function<bool(int)>& serves) {
  int failed = last;  // the lowest point known to fail
  int found = -1;
  for (int gap = 1; found < 0 && last - gap >= 1; gap *= 2) {
    const int i = last - gap;
    if (serves(i)) found = i;
    else failed = i;
  }
  if (found < 0 && failed > 1 && serves(1)) found = 1;  // the descent stepped over the lowest points
  if (found < 0) return -1;
  // Between the point that serves and the failing one after it.
  for (int lo = found + 1, hi = failed - 1; lo <= hi;) {
    const int mid = (lo + hi + 1) / 2;
    if (serves(mid)) {
      found = mid;
      lo = mid + 1;
    } else {
      hi = mid - 1;
    }
  }
  return found;
}

int highest_serving_point(const std::vector<double>& levels, double full, const std::function<bool(int)>& serves) {
  // The candidates in order of increasing level (the path's order among equal levels); the
  // last is the full excitation, where Newton has just failed, and the first the preload-only
  // state.
  std::vector<int> order;
  for (int i = 1; i + 1 < static_cast<int>(levels.size()); ++i)
    if (levels[static_cast<std::size_t>(i)] > 0.0 && levels[static_cast<std::size_t>(i)] < full) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&levels](int a, int b) {
    return levels[static_cast<std::size_t>(a)] < levels[static_cast<std::size_t>(b)];
  });
  // Rank k (1 .. size) is order[k - 1]; rank size + 1 stands for the full excitation.
  const int rank = last_serving_point(static_cast<int>(order.size()) + 1,
                                      [&](int k) { return serves(order[static_cast<std::size_t>(k - 1)]); });
  return rank < 0 ? -1 : order[static_cast<std::size_t>(rank - 1)];
}

namespace {

// Where the excitation homotopy at a stepping level can start instead of the preload-only
// state: the point of a lower level's homotopy path (`lower`, with `lower_h` harmonics) at the
// highest excitation level that can be found (highest_serving_point) from which Newton at this
// level converges (the point padded with zero new harmonics). Returns scale 0 when no point
// serves.
HomotopyStart resume_point(const std::vector<continuation::BranchPoint>& lower, int lower_h, ReducedEquations& level,
                           const hbm::ContactEvaluator& evaluator, double f, const continuation::ArclengthOptions& ao) {
  HomotopyStart best;
  const double full = level.excitation_scale();
  // Newton at this level from point i of the lower path; `best` takes it when it converges.
  auto serves = [&](int i) {
    const continuation::BranchPoint& p = lower[static_cast<std::size_t>(i)];
    Eigen::VectorXd w = with_more_harmonics(p.x, lower_h, evaluator);
    level.set_excitation_scale(p.lambda);
    if (continuation::newton_fixed(level, w, f, ao) < 0) return false;
    best.scale = p.lambda;
    best.x = std::move(w);
    return true;
  };
  std::vector<double> levels(lower.size());
  for (std::size_t i = 0; i < lower.size(); ++i) levels[i] = lower[i].lambda;
  highest_serving_point(levels, full, serves);  // `best` keeps what it found
  level.set_excitation_scale(full);
  return best;
}

// The start search at one frequency (see find_start); throws NumericalError.
Eigen::VectorXd find_start_at(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                              ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                              std::string& how, const Info& info) {
  const double x_scale = ao.x_scale[0];
  const log::Stopwatch clock;
  auto after = [&] { return " (after " + fixed(clock.seconds(), 1) + " s)"; };
  how = "stuck contact";
  Eigen::VectorXd start = equations.stuck_solution(f);
  {
    // Equations that cannot be evaluated here have no solution to find: say why.
    Eigen::VectorXd r;
    if (!start.allFinite() || !equations.evaluate(start, f, r, nullptr, nullptr) || !r.allFinite())
      throw NumericalError("the harmonic-balance equations are not finite at " + shortest(f) +
                           " Hz: a harmonic of this frequency lies on a natural frequency without damping (the "
                           "receptance is infinite there); give the structure damping or start the range elsewhere");
  }
  if (continuation::newton_fixed(equations, start, f, ao) >= 0) return start;
  how = "free response";
  start = equations.linear_motion(f);
  if (continuation::newton_fixed(equations, start, f, ao) >= 0) return start;
  if (eo.n_harmonics > 1) {
    // Harmonic stepping: solve the start with H = 1, then raise H one harmonic at a time,
    // each new harmonic starting at zero (higher harmonics are small corrections). A level
    // that Newton does not reach from the one below is reached by the excitation homotopy at
    // that level: its unknowns are h / H of the case's, so a path of the same length costs a
    // fraction of the homotopy at H (docs/continuation.md, "Start"). Level H itself is left
    // to the homotopy below, which is the same computation.
    say(info, "frf: no start at " + shortest(f) + " Hz from the stuck or the free state" + after() +
                  "; trying harmonic stepping");
    Eigen::VectorXd prev;
    int prev_h = 0;
    std::string by_homotopy;     // the levels reached by the excitation homotopy ("2, 3")
    continuation::Branch lower;  // the path of the last of them
    int lower_h = 0;
    for (int h = 1; h <= eo.n_harmonics; ++h) {
      hbm::ContactEvaluatorOptions step_options = eo;
      step_options.n_harmonics = h;
      hbm::ContactEvaluator step_evaluator(step_options, model.pairs);
      ReducedEquations step_equations(*model.linear, step_evaluator);
      step_equations.set_excitation_scale(equations.excitation_scale());  // nlmodes traces scaled ones
      continuation::ArclengthOptions so = ao;
      so.x_scale = Eigen::VectorXd::Constant(step_equations.size(), x_scale);
      Eigen::VectorXd w;
      if (h == 1) {
        w = step_equations.stuck_solution(f);
      } else {
        w = with_more_harmonics(prev, prev_h, step_evaluator);
      }
      if (continuation::newton_fixed(step_equations, w, f, so) < 0) {
        if (h == eo.n_harmonics) break;
        // The part of the lower level's path where this level's Newton converges from it is
        // not traced again (docs/continuation.md, "Start").
        const HomotopyStart from = lower.points.empty()
                                       ? HomotopyStart{}
                                       : resume_point(lower.points, lower_h, step_equations, step_evaluator, f, so);
        continuation::Branch b =
            solve_by_excitation_homotopy(step_equations, f, so, w, from.scale > 0.0 ? &from : nullptr);
        if (b.status != continuation::BranchStatus::kReachedEnd) break;
        say(info, "frf: H = " + std::to_string(h) + " at " + shortest(f) +
                      " Hz by continuation in the excitation level (" + std::to_string(b.points.size()) + " points" +
                      (from.scale > 0.0
                           ? " from s = " + shortest(from.scale) + " on the path of H = " + std::to_string(lower_h)
                           : std::string()) +
                      ")" + after());
        by_homotopy += (by_homotopy.empty() ? "" : ", ") + std::to_string(h);
        lower = std::move(b);
        lower_h = h;
      }
      prev = w;
      prev_h = h;
    }
    if (prev_h == eo.n_harmonics) {
      how = "harmonic stepping";
      if (!by_homotopy.empty()) how += " (the excitation homotopy at H = " + by_homotopy + ")";
      say(info, "frf: start point at " + shortest(f) + " Hz by harmonic stepping (H = 1 .. " +
                    std::to_string(eo.n_harmonics) + ")" + after());
      return prev;
    }
  }
  how = "excitation homotopy";
  say(info, "frf: no start at " + shortest(f) + " Hz by Newton" + after() +
                "; trying the continuation in the excitation level");
  const continuation::Branch h = solve_by_excitation_homotopy(equations, f, ao, start);
  if (h.status != continuation::BranchStatus::kReachedEnd)
    throw NumericalError(
        "no solution at the start frequency " + shortest(f) +
        " Hz: Newton failed from the stuck-contact state and the continuation in the excitation level stopped: " +
        h.message);
  say(info, "frf: start point found by continuation in the excitation level (" + std::to_string(h.points.size()) +
                " points, " + std::to_string(h.newton_iterations) + " Newton iterations, " +
                std::to_string(h.rejected_steps) + " rejected steps of which " + std::to_string(h.rejected_turns) +
                " turned too far, " + std::to_string(h.kinks_crossed) + " corners crossed)" + after());
  return start;
}

// Where the harmonic balance finds no start at f, a lumped model is integrated in time from
// rest (forced/time_march.hpp): a periodic motion gives the start (Newton from its harmonics);
// a motion that does not repeat every excitation period is the reason, in `why`.
constexpr int kPatientNewtonIterations = 100;
constexpr int kFinerTimeSamples = 1024;

// The time integration's output: 4096 samples per period whatever the harmonic balance's N (the
// steps per period are a multiple of it, and at least 4096 anyway; a finer N takes its own), so
// that the attempts with a raised N (pipeline, hbm.raise_time_samples: N, 4 N, 16 N up to
// 4096) and the points of a convergence study in N march once, not once each.
constexpr int kMarchOutputSamples = 4096;

bool start_from_time_march(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                           ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                           Eigen::VectorXd& x, std::string& how, std::string& why, bool& not_periodic,
                           const Info& info) {
  const auto* lumped = dynamic_cast<const frf::LumpedLinearPart*>(model.linear.get());
  if (lumped == nullptr) return false;
  LumpedSystem system = lumped_system(*lumped);
  system.force *= equations.excitation_scale();  // the level these equations carry
  TimeMarchOptions to;
  to.output_samples = std::max(eo.n_time_samples, kMarchOutputSamples);
  bool reused = false;
  say(info, "frf: no harmonic-balance start at " + shortest(f) + " Hz; integrating the equations of motion in time");
  const TimeMarchResult tm = march_to_steady_state_cached(system, model.pairs, eo.law.model, f, to, &reused);
  if (reused) say(info, "frf: (the time integration at " + shortest(f) + " Hz of an earlier attempt, reused)");
  const std::string what = "the motion at " + shortest(f) + " Hz is " + tm.describe();
  // A motion that still changes by up to a percent from period to period may be periodic to
  // the scheme's resolution of its stick-slip and impact instants (a step quantizes them): it
  // is tried as a start too, and only a converged harmonic balance counts.
  constexpr double kNearlyPeriodic = 1e-2;
  const bool nearly = tm.motion == TimeMarchResult::Motion::not_settled && tm.change_one_period < kNearlyPeriodic;
  if (tm.motion != TimeMarchResult::Motion::periodic && !nearly) {
    why = what;
    not_periodic = true;
    return false;
  }
  x = harmonic_unknowns(tm.contact_motion, eo.n_harmonics, contact::n_directions(eo.law.model));
  // The guess is near the solution but the sampled law's corners make plain Newton cycle:
  // more iterations (each with its backtracking) than a continuation step gets.
  continuation::ArclengthOptions patient = ao;
  patient.max_newton_iterations = std::max(ao.max_newton_iterations, kPatientNewtonIterations);
  if (continuation::newton_fixed(equations, x, f, patient) >= 0) {
    how = "time integration (" + std::to_string(tm.periods) + " periods), then Newton";
    say(info, "frf: start point at " + shortest(f) + " Hz from " + how);
    return true;
  }
  // Which discretization does have a solution there: the same harmonics with a finer sampling
  // of the period (the sampled law's stick-slip corners are what Newton cycles between), then
  // twice the harmonics (a truncation that misses the motion's corners).
  const std::string none =
      (nearly ? "; taken as nearly periodic, Newton from its last period's harmonics" : "; Newton from its harmonics") +
      std::string(" does not converge with H = ") + std::to_string(eo.n_harmonics) +
      ", N = " + std::to_string(eo.n_time_samples);
  std::string tried;
  for (const int h : {eo.n_harmonics, 2 * eo.n_harmonics}) {
    hbm::ContactEvaluatorOptions finer = eo;
    finer.n_harmonics = h;
    finer.n_time_samples = std::max(eo.n_time_samples, kFinerTimeSamples);
    if (2 * h + 1 > tm.contact_motion.cols() || 2 * h + 1 > finer.n_time_samples) continue;
    if (h == eo.n_harmonics && finer.n_time_samples == eo.n_time_samples) continue;
    const std::string settings = "H = " + std::to_string(h) + ", N = " + std::to_string(finer.n_time_samples);
    hbm::ContactEvaluator evaluator(finer, model.pairs);
    ReducedEquations fine(*model.linear, evaluator);
    fine.set_excitation_scale(equations.excitation_scale());  // the level the motion was integrated at
    Eigen::VectorXd xf = harmonic_unknowns(tm.contact_motion, h, contact::n_directions(eo.law.model));
    continuation::ArclengthOptions fo = patient;
    fo.x_scale = Eigen::VectorXd::Constant(xf.size(), ao.x_scale[0]);
    if (continuation::newton_fixed(fine, xf, f, fo) >= 0) {
      why = what + none + " but does with " + settings + ": raise hbm.time_samples" +
            (h > eo.n_harmonics ? " and hbm.harmonics" : "") +
            " (the coarser discretization has no solution near this motion)";
      return false;
    }
    tried += (tried.empty() ? "" : ", ") + settings;
  }
  why = what + none + (tried.empty() ? "" : " (nor with " + tried + ")");
  return false;
}

Eigen::VectorXd find_start_logged(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                                  ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                                  std::string& how, const Info& info) {
  try {
    return find_start_at(model, eo, equations, ao, f, how, info);
  } catch (const NumericalError& first) {
    // Every start can fail at one frequency and work a little way off it (the excitation
    // homotopy meets a sampled stick-slip corner). Start nearby, then walk to f by Newton at
    // fixed frequencies.
    for (double offset : {0.002, -0.002, 0.005, -0.005, 0.01, -0.01}) {
      const double g = f * (1.0 + offset);
      std::string how_g;
      Eigen::VectorXd x;
      try {
        x = find_start_at(model, eo, equations, ao, g, how_g, info);
      } catch (const NumericalError&) {
        continue;
      }
      constexpr int kWalkSteps = 4;
      bool ok = true;
      for (int k = 1; k <= kWalkSteps && ok; ++k)
        ok = continuation::newton_fixed(equations, x, g + (f - g) * k / kWalkSteps, ao) >= 0;
      if (!ok) continue;
      how = how_g + " at " + shortest(g) + " Hz, then Newton to " + shortest(f) + " Hz";
      say(info, "frf: start point at " + shortest(f) + " Hz from " + how);
      return x;
    }
    Eigen::VectorXd x;
    std::string why;
    bool not_periodic = false;
    if (start_from_time_march(model, eo, equations, ao, f, x, how, why, not_periodic, info)) return x;
    const std::string message = std::string(first.what()) + "; time integration: " + why;
    if (not_periodic) throw NoPeriodicMotion(message);
    if (!why.empty()) throw NumericalError(message);
    throw;
  }
}

void add_counts(continuation::Branch& to, const continuation::Branch& b) {
  to.turning_points += b.turning_points;
  to.smooth_folds += b.smooth_folds;
  to.newton_iterations += b.newton_iterations;
  to.rejected_steps += b.rejected_steps;
  to.rejected_turns += b.rejected_turns;
  to.kinks_crossed += b.kinks_crossed;
  to.reflections_crossed += b.reflections_crossed;
  to.residual_evaluations += b.residual_evaluations;
}

/// Whether every frequency between a and b lies between the lowest and the highest frequency
/// of some piece (null pieces are skipped): each piece is one continuous path of solutions,
/// so together they have a solution at every frequency of the range.
bool extents_cover(const std::vector<const std::vector<continuation::BranchPoint>*>& pieces, double a, double b) {
  std::vector<std::pair<double, double>> spans;
  for (const auto* piece : pieces) {
    if (!piece || piece->empty()) continue;
    double lo = piece->front().lambda, hi = lo;
    for (const auto& p : *piece) lo = std::min(lo, p.lambda), hi = std::max(hi, p.lambda);
    spans.emplace_back(lo, hi);
  }
  std::sort(spans.begin(), spans.end());
  double covered = std::min(a, b);
  for (const auto& [lo, hi] : spans) {
    if (lo > covered) return false;
    covered = std::max(covered, hi);
  }
  return covered >= std::max(a, b);
}

// The number of pieces of a curve (its largest piece number + 1; 0 without points).
int piece_count(const FrequencyResponse& out) {
  return out.piece.empty() ? 0 : *std::max_element(out.piece.begin(), out.piece.end()) + 1;
}

// The stretches of [lo, hi] that no piece spans (a piece spans its lowest to its highest
// frequency), from low to high.
std::vector<std::pair<double, double>> uncovered_stretches(const std::vector<continuation::BranchPoint>& points,
                                                           const std::vector<int>& piece, double lo, double hi) {
  std::vector<std::pair<double, double>> spans;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(piece[i]);
    if (spans.size() <= k)
      spans.resize(k + 1, {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()});
    spans[k].first = std::min(spans[k].first, points[i].lambda);
    spans[k].second = std::max(spans[k].second, points[i].lambda);
  }
  std::sort(spans.begin(), spans.end());
  // A piece that reached an end is put on it to the tracing's slack (continuation::trace).
  const double slack = 1e-9 * (hi - lo);
  std::vector<std::pair<double, double>> gaps;
  double covered = lo;
  for (const auto& [a, b] : spans) {
    if (!(a <= b)) continue;  // a piece number without points
    if (a > covered + slack) gaps.emplace_back(covered, std::min(a, hi));
    covered = std::max(covered, b);
    if (covered >= hi) break;
  }
  if (covered < hi - slack) gaps.emplace_back(covered, hi);
  return gaps;
}

double total_length(const std::vector<std::pair<double, double>>& stretches) {
  double sum = 0.0;
  for (const auto& [a, b] : stretches) sum += b - a;
  return sum;
}

// Hops (docs/continuation.md, "Hops past a stopped piece"): at most this many new starts.
constexpr int kMaxHops = 6;

// Where the pieces leave part of the range without a solution (a piece closed on itself on a
// loop of the sampled law, turned back, or stalled, and the far end has no start), a start is
// sought inside the uncovered stretch: Newton at fixed frequency from the point of the piece
// that ends there, 1, 4 and 16 initial steps in; then the whole start search in the stretch's
// middle. From it a piece is traced to each end of the stretch and a little past (to meet the
// piece there). Each new piece is one continuous path of solutions, so the range is covered
// when no stretch is left; whether the new pieces join the ones they run into is the join test
// of the second piece. Returns whether the range is covered; `notes` says what was tried, and
// `joined` is cleared when a new piece that reached a neighbour does not join it.
bool hop_over_gaps(FrequencyResponse& out, const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                   ReducedEquations& equations, const continuation::ArclengthOptions& ao,
                   const std::function<void(const continuation::BranchPoint&, int)>& progress, const Info& info,
                   std::string& notes, bool& joined) {
  const double lo = std::min(ao.lambda_start, ao.lambda_end), hi = std::max(ao.lambda_start, ao.lambda_end);
  const double direction = ao.lambda_end > ao.lambda_start ? 1.0 : -1.0;
  const double step_hz = ao.initial_step * ao.lambda_scale;
  const double overlap = 4.0 * step_hz;
  auto note = [&](const std::string& s) { notes += (notes.empty() ? "" : "; ") + s; };
  for (int hop = 0; hop < kMaxHops; ++hop) {
    const auto gaps = uncovered_stretches(out.points, out.piece, lo, hi);
    if (gaps.empty()) return true;
    const int left = ao.max_points - static_cast<int>(out.points.size());
    if (left < 4) {
      note("no points left to fill " + shortest(gaps.front().first) + " .. " + shortest(gaps.front().second) + " Hz");
      return false;
    }
    // The first stretch in the direction of travel.
    const auto [a, b] = direction > 0 ? gaps.front() : gaps.back();
    // Seeds: the points of the pieces at the stretch's ends (none at an end of the range).
    struct Seed {
      double lambda;
      const continuation::BranchPoint* from;
    };
    std::vector<Seed> seeds;
    auto nearest = [&](double f) {
      const continuation::BranchPoint* best = nullptr;
      for (const auto& p : out.points)
        if (!best || std::abs(p.lambda - f) < std::abs(best->lambda - f)) best = &p;
      return best;
    };
    for (double in : {1.0, 4.0, 16.0}) {
      const double d = in * step_hz;
      if (2.0 * d >= b - a) break;
      if (a > lo && !out.points.empty()) seeds.push_back({a + d, nearest(a)});
      if (b < hi && !out.points.empty()) seeds.push_back({b - d, nearest(b)});
    }
    Eigen::VectorXd x;
    double f0 = 0.0;
    std::string how;
    for (const Seed& s : seeds) {
      Eigen::VectorXd guess = s.from->x;
      if (continuation::newton_fixed(equations, guess, s.lambda, ao) >= 0) {
        x = guess;
        f0 = s.lambda;
        how = "Newton from the point at " + shortest(s.from->lambda) + " Hz";
        break;
      }
    }
    if (x.size() == 0) {
      const double mid = 0.5 * (a + b);
      try {
        x = find_start_logged(model, eo, equations, ao, mid, how, info);
        f0 = mid;
      } catch (const NumericalError& e) {
        note("no start in " + shortest(a) + " .. " + shortest(b) + " Hz (Newton from the pieces' ends failed; at " +
             shortest(mid) + " Hz: " + e.what() + ")");
        return false;
      }
    }
    ++out.hops;
    say(info, "frf: no solution traced in " + shortest(a) + " .. " + shortest(b) + " Hz; a start at " + shortest(f0) +
                  " Hz (" + how + "), traced both ways");
    const double before = total_length(gaps);
    for (const double bound : {std::min(hi, b + overlap), std::max(lo, a - overlap)}) {
      if (!(std::abs(bound - f0) > 0)) continue;
      continuation::ArclengthOptions o = ao;
      o.lambda_start = f0;
      o.lambda_end = bound;
      o.max_points = std::max(2, (ao.max_points - static_cast<int>(out.points.size())) / 2);
      const continuation::Branch piece = continuation::trace(equations, x, o);
      add_counts(out.summary, piece);
      if (piece.points.empty()) continue;
      const int k = piece_count(out);  // the new piece's number
      // Reached a neighbouring piece: it joins if its last point lies on one.
      const bool neighbour = piece.status == continuation::BranchStatus::kReachedEnd && bound > lo && bound < hi;
      if (neighbour) {
        double d = std::numeric_limits<double>::infinity();
        for (int j = 0; j < k; ++j) {
          std::vector<continuation::BranchPoint> pts;
          for (std::size_t i = 0; i < out.points.size(); ++i)
            if (out.piece[i] == j) pts.push_back(out.points[i]);
          d = std::min(d, continuation::distance_to_branch(equations, ao, pts, piece.points.back()));
        }
        out.join_distance = std::max(out.join_distance, d);
        if (!(d <= kJoinTolerance)) joined = false;
      } else if (piece.status != continuation::BranchStatus::kReachedEnd) {
        joined = false;  // it stopped short of the piece beyond: no join measured
        out.join_distance = std::numeric_limits<double>::infinity();
      }
      for (const auto& p : piece.points) {
        out.points.push_back(p);
        out.piece.push_back(k);
        if (progress) progress(p, k);
      }
      note("piece " + std::to_string(k) + " from " + shortest(f0) + " Hz (" + how + ") towards " + shortest(bound) +
           " Hz: " + (piece.message.empty() ? std::string("reached it") : piece.message));
    }
    if (!(total_length(uncovered_stretches(out.points, out.piece, lo, hi)) < before)) {
      note("the hop covered nothing new");
      return false;
    }
  }
  const bool covered = uncovered_stretches(out.points, out.piece, lo, hi).empty();
  if (!covered) note("stopped after " + std::to_string(kMaxHops) + " hops");
  return covered;
}

}  // namespace

double free_motion_peak(const frf::LinearPart& linear, const ReducedEquations& equations, double f_start,
                        double f_end) {
  std::vector<double> at;
  for (int i = 0; i <= 40; ++i) at.push_back(f_start + (f_end - f_start) * i / 40.0);
  const double lo = std::min(f_start, f_end), hi = std::max(f_start, f_end);
  for (double f : linear.resonances_hz())
    if (f > lo && f < hi) at.push_back(f);
  // An undamped resonance in the range has an unbounded free response there: such samples
  // do not set the unit (the friction bounds the forced response; the others do).
  double motion = 0.0;
  for (double f : at) {
    const double m = equations.linear_motion(f).lpNorm<Eigen::Infinity>();
    if (std::isfinite(m)) motion = std::max(motion, m);
  }
  return motion;
}

continuation::ArclengthOptions arclength_options(const FrequencyResponseSettings& s, const ForcedModel& model,
                                                 const ReducedEquations& equations) {
  const double motion = free_motion_peak(*model.linear, equations, s.frequency_start_hz, s.frequency_end_hz);
  double contact_scale = 0.0;
  for (const auto& p : model.pairs)
    contact_scale =
        std::max({contact_scale, p.friction_coefficient * std::abs(p.normal_preload) / p.tangential_stiffness,
                  std::abs(p.normal_preload) / p.normal_stiffness});
  const double x_unit = motion > 0 ? motion / kFreePeakUnits
                                   : (contact_scale > 0 && std::isfinite(contact_scale) ? contact_scale : 1.0);
  const double lambda_unit = std::abs(s.frequency_end_hz - s.frequency_start_hz) / kRangeUnits;
  continuation::ArclengthOptions ao;
  ao.lambda_start = s.frequency_start_hz;
  ao.lambda_end = s.frequency_end_hz;
  ao.lambda_scale = lambda_unit;
  ao.x_scale = Eigen::VectorXd::Constant(equations.size(), x_unit);
  const double requested = s.initial_step_hz > 0 ? s.initial_step_hz / lambda_unit : kAutoInitialStep;
  ao.initial_step = std::min(requested, kMaxStep);
  ao.max_step = kMaxArcStep / ao.initial_step;
  ao.max_lambda_step = kMaxStep;
  ao.max_points = s.max_points;
  ao.tolerance = s.tolerance;
  return ao;
}

Eigen::VectorXd find_start(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                           ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                           std::string& how) {
  return find_start_logged(model, eo, equations, ao, f, how, {});
}

std::vector<std::size_t> prominent_maxima(const std::vector<double>& a, double min_prominence) {
  std::vector<std::size_t> out;
  const std::size_t m = a.size();
  for (std::size_t i = 0; i < m; ++i) {
    const bool left_ok = i == 0 || a[i] > a[i - 1];
    const bool right_ok = i + 1 == m || a[i] >= a[i + 1];
    if (!left_ok || !right_ok) continue;
    double left_min = a[i], right_min = a[i];
    for (std::size_t j = i; j-- > 0 && a[j] <= a[i];) left_min = std::min(left_min, a[j]);
    for (std::size_t j = i + 1; j < m && a[j] <= a[i]; ++j) right_min = std::min(right_min, a[j]);
    // At an end of the curve the drop is only known on one side.
    const double base = i == 0 ? right_min : i + 1 == m ? left_min : std::max(left_min, right_min);
    if (a[i] > 0 && a[i] - base >= min_prominence * a[i]) out.push_back(i);
  }
  return out;
}

bool is_sampled_top(const ResponsePeak& peak, const std::array<const continuation::BranchPoint*, 3>& top,
                    double sampled_amplitude, const Eigen::VectorXd& x_scale, double lambda_scale) {
  // The amplitude of a traced point is known to about the corrector's tolerance (1e-8 of the
  // x unit by default); a located maximum of the same top is at least as high to well within
  // this.
  constexpr double kAmplitudeSlack = 1e-6;
  constexpr double kStepFraction = 0.25;
  const bool unscaled = x_scale.size() == 0;
  if (!peak.located || (!unscaled && peak.x.size() != x_scale.size())) return false;
  if (peak.amplitude_m < (1.0 - kAmplitudeSlack) * sampled_amplitude) return false;
  auto scaled = [&](const Eigen::VectorXd& x, double lambda) {
    Eigen::VectorXd y(x.size() + 1);
    if (unscaled) y.head(x.size()) = x;
    else y.head(x.size()) = x.cwiseQuotient(x_scale);
    y[x.size()] = lambda / lambda_scale;
    return y;
  };
  const Eigen::VectorXd q = scaled(peak.x, peak.frequency_hz);
  double longest = 0.0, nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd a = scaled(top[k]->x, top[k]->lambda), b = scaled(top[k + 1]->x, top[k + 1]->lambda);
    const Eigen::VectorXd ab = b - a;
    const double length2 = ab.squaredNorm();
    longest = std::max(longest, std::sqrt(length2));
    const double t = length2 > 0.0 ? std::clamp((q - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (q - a - t * ab).norm());
  }
  return nearest <= kStepFraction * longest;
}

namespace {

// The results of every point (energy balance polished where it misses) and the located peaks.
void analyse_and_locate_peaks(FrequencyResponse& out, const FrequencyResponseSettings& settings,
                              const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                              ReducedEquations& equations, const continuation::ArclengthOptions& ao) {
  for (auto& p : out.points) {
    out.results.push_back(equations.analyse(p.x, p.lambda));
    // The energy balance is only as good as W: the corrector's tolerance is relative to the
    // x unit (the free motion), which can exceed the motion at a point by orders of magnitude
    // (a stiff stuck contact nearly clamping the structure). A point whose balance misses is
    // polished once by Newton at its own scale before it is judged.
    if (out.results.back().energy_error > kPolishAbove) {
      continuation::ArclengthOptions fine = ao;
      const double own = p.x.lpNorm<Eigen::Infinity>();
      if (!(own > 0)) continue;
      fine.x_scale = Eigen::VectorXd::Constant(p.x.size(), own);
      fine.tolerance = kPolishTolerance;
      Eigen::VectorXd x = p.x;
      if (continuation::newton_fixed(equations, x, p.lambda, fine) >= 0) {
        PointResult polished = equations.analyse(x, p.lambda);
        if (polished.energy_error < out.results.back().energy_error) {
          p.x = x;
          out.results.back() = polished;
          ++out.polished_points;
        }
      }
    }
  }

  // Resonance peaks, located along the branch: every prominent sampled maximum first, each
  // with equations of its own (a fresh evaluator and preconditioner: its result does not
  // depend on the order, the worker count or what was solved before it), on up to `threads`
  // workers; then in order, skipping tops located before.
  const auto t0 = std::chrono::steady_clock::now();
  struct Candidate {
    std::size_t i = 0;  // the sampled maximum's point
    int piece = 0;
    bool inner = false;  // with a point on either side in its piece
    std::array<const continuation::BranchPoint*, 3> pts{};
    std::array<double, 3> amp{};
    continuation::Extremum best;
    int evaluations = 0;
    SolverStatistics statistics;
  };
  std::vector<Candidate> candidates;
  const int n_pieces = piece_count(out);
  for (int pc = 0; pc < n_pieces; ++pc) {
    std::vector<std::size_t> idx;
    std::vector<double> amp;
    for (std::size_t i = 0; i < out.points.size(); ++i)
      if (out.piece[i] == pc) idx.push_back(i), amp.push_back(out.results[i].amplitude);
    constexpr double kMinProminence = 0.02;  // a local maximum 2 % above its surroundings
    for (std::size_t m : prominent_maxima(amp, kMinProminence)) {
      Candidate cd;
      cd.i = idx[m];
      cd.piece = pc;
      cd.inner = m > 0 && m + 1 < idx.size();
      if (cd.inner) {
        cd.pts = {&out.points[idx[m - 1]], &out.points[cd.i], &out.points[idx[m + 1]]};
        cd.amp = {out.results[idx[m - 1]].amplitude, out.results[cd.i].amplitude, out.results[idx[m + 1]].amplitude};
      }
      candidates.push_back(cd);
    }
  }
  auto locate = [&](Candidate& cd) {
    hbm::ContactEvaluator evaluator(eo, model.pairs);
    ReducedEquations own(*model.linear, evaluator);
    own.set_linear_solver(equations.linear_solver());
    own.set_excitation_scale(equations.excitation_scale());
    int evaluations = 0;
    continuation::ScaledSystem sys(own, ao, &evaluations);
    continuation::ArclengthOptions fine = ao;
    const double size = out.points[cd.i].x.lpNorm<Eigen::Infinity>();
    const double unit = ao.x_scale.size() > 0 ? ao.x_scale.maxCoeff() : 1.0;
    if (size > 0 && unit > 0) fine.tolerance = std::min(ao.tolerance, kPeakTolerance * size / unit);
    const Amplitude amplitude = [&](const Eigen::VectorXd& x, double lambda) {
      return own.analyse(x, lambda).amplitude;
    };
    // On the two steps beside the sampled maximum, each parametrized by the arclength along
    // the tangent of its first point.
    std::array<double, 2> lengths{0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      const continuation::BranchPoint& p = *cd.pts[k];
      const continuation::BranchPoint& q = *cd.pts[k + 1];
      lengths[k] = p.tangent.dot(sys.to_scaled(q.x, q.lambda) - sys.to_scaled(p.x, p.lambda));
      if (!(lengths[k] > 0)) continue;
      // At the tight tolerance; where the corrector cannot reach it, at the tracing one.
      continuation::Extremum e = continuation::locate_maximum(own, fine, p, lengths[k], amplitude);
      cd.evaluations += e.evaluations;
      if (!e.found) {
        e = continuation::locate_maximum(own, ao, p, lengths[k], amplitude);
        cd.evaluations += e.evaluations;
      }
      keep_larger(cd.best, e);
    }
    if (cd.best.found)
      cd.best = search_rippled_top(own, fine, ao, cd.pts, cd.amp, lengths, cd.best, amplitude, cd.evaluations);
    cd.statistics = own.statistics();
  };
  std::vector<std::size_t> to_locate;
  if (settings.locate_peaks)
    for (std::size_t k = 0; k < candidates.size(); ++k)
      if (candidates[k].inner) to_locate.push_back(k);
  // The tallest first: its top is the most rippled, the longest job (the results do not depend
  // on the order).
  std::stable_sort(to_locate.begin(), to_locate.end(),
                   [&](std::size_t a, std::size_t b) { return candidates[a].amp[1] > candidates[b].amp[1]; });
  const int jobs = static_cast<int>(to_locate.size());
  linalg::parallel_for(jobs, linalg::worker_count(eo.threads, jobs),
                       [&](int j) { locate(candidates[to_locate[static_cast<std::size_t>(j)]]); });
  for (const Candidate& cd : candidates) {
    ResponsePeak peak{out.points[cd.i].lambda, out.results[cd.i].amplitude, cd.i, cd.piece, false, out.points[cd.i].x};
    out.summary.residual_evaluations += cd.evaluations;
    equations.add_statistics(cd.statistics);
    if (cd.inner) {
      // A top the curve has already passed over and located (a piece that turns back over
      // it, or an earlier piece that overlaps this one): not reported again.
      // The geometric test picks the candidates; the corrector confirms that the located peak
      // is a solution of the branch these three points sample (a twin branch a sample away
      // stays at its own distance), as closes_loop does for a closed loop.
      constexpr double kSameBranchTolerance = 100.0;  // in units of the tracing tolerance
      const bool copy = std::any_of(out.peaks.begin(), out.peaks.end(), [&](const ResponsePeak& q) {
        if (!is_sampled_top(q, cd.pts, out.results[cd.i].amplitude, ao.x_scale, ao.lambda_scale)) return false;
        continuation::BranchPoint located;
        located.x = q.x;
        located.lambda = q.frequency_hz;
        const std::vector<continuation::BranchPoint> sampled{*cd.pts[0], *cd.pts[1], *cd.pts[2]};
        return continuation::distance_to_branch(equations, ao, sampled, located) <= kSameBranchTolerance * ao.tolerance;
      });
      if (copy) continue;
    }
    if (cd.best.found) {
      peak.located = true;  // if no trial point beats the sampled one, it is the maximum to tolerance
      if (cd.best.value > peak.amplitude_m)
        peak.amplitude_m = cd.best.value, peak.frequency_hz = cd.best.lambda, peak.x = cd.best.x;
    }
    out.peaks.push_back(peak);
  }
  out.peaks = distinct_peaks(std::move(out.peaks), ao.lambda_scale);
  out.peak_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A curve that stopped short (not at max_points) with part of the range uncovered: the hops
// (hop_over_gaps). Covered: the curve reaches the end, in pieces, with a warning that says so;
// otherwise what the hops tried is added to the reason it stopped.
void hop_if_uncovered(FrequencyResponse& out, const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                      ReducedEquations& equations, const continuation::ArclengthOptions& ao,
                      const std::function<void(const continuation::BranchPoint&, int)>& progress, const Info& info) {
  const auto status = out.summary.status;
  if (status == continuation::BranchStatus::kReachedEnd || status == continuation::BranchStatus::kMaxPoints) return;
  const std::string stopped = out.summary.message;
  std::string notes;
  bool joined = out.pieces_join;
  const std::size_t before = out.points.size();
  if (hop_over_gaps(out, model, eo, equations, ao, progress, info, notes, joined)) {
    out.pieces_join = joined;
    out.two_pieces = true;
    out.summary.status = continuation::BranchStatus::kReachedEnd;
    out.summary.message = "";
    out.warnings.push_back(
        "the curve is " + std::to_string(piece_count(out)) + " pieces" +
        (joined ? " that join" : " that together cover the range but were not all shown to be one branch") +
        ": the pieces traced from the ends stopped (" + (stopped.empty() ? "no start" : stopped) +
        "), and starts past where they stopped gave the rest: " + notes + " (frf.csv column `piece`)");
  } else {
    out.summary.message = stopped + "; " + (out.points.size() > before ? "past where it stopped: " : "") + notes;
  }
}

FrequencyResponse trace_from(const FrequencyResponseSettings& settings, const ForcedModel& model,
                             const hbm::ContactEvaluatorOptions& eo, ReducedEquations& equations,
                             const std::function<void(const continuation::BranchPoint&, int)>& progress,
                             const Info& info, bool may_reverse) {
  FrequencyResponse out;
  const continuation::ArclengthOptions ao = arclength_options(settings, model, equations);
  out.options = ao;
  Eigen::VectorXd start;
  try {
    start = find_start_logged(model, eo, equations, ao, ao.lambda_start, out.start, info);
  } catch (const NumericalError& e) {
    // No start at the start of the range: the whole range traced from its other end (the
    // same curve, travelled the other way); if that has no start either, both reasons.
    if (!may_reverse) throw;
    say(info, "frf: no start at " + shortest(ao.lambda_start) + " Hz (" + e.what() + "); tracing from " +
                  shortest(ao.lambda_end) + " Hz instead");
    FrequencyResponseSettings reversed = settings;
    std::swap(reversed.frequency_start_hz, reversed.frequency_end_hz);
    try {
      FrequencyResponse r = trace_from(reversed, model, eo, equations, progress, info, false);
      r.start = "from the end of the range, " + r.start + " (none at " + shortest(ao.lambda_start) + " Hz)";
      return r;
    } catch (const NumericalError& e2) {
      std::string both = std::string(e.what()) + "; from the end of the range, " + shortest(ao.lambda_end) +
                         " Hz, none either: " + e2.what();
      // No start at either end: a start inside the range, traced both ways (hop_over_gaps).
      out.summary.status = continuation::BranchStatus::kStartFailed;
      std::string notes;
      bool joined = true;
      if (hop_over_gaps(out, model, eo, equations, ao, progress, info, notes, joined)) {
        out.start = "inside the range (none at either end: " + both + ")";
        out.pieces_join = joined;
        out.two_pieces = true;
        out.summary.status = continuation::BranchStatus::kReachedEnd;
        out.warnings.push_back("no start at either end of the range; the curve was traced from inside it: " + notes +
                               (joined ? "" : " (not all shown to be one branch)") + " (frf.csv column `piece`)");
        analyse_and_locate_peaks(out, settings, model, eo, equations, ao);
        return out;
      }
      both += "; inside the range: " + notes;
      if (!out.points.empty()) {
        // Pieces were traced inside the range but do not cover it: written with the reason.
        out.start = "inside the range (none at either end)";
        out.pieces_join = false;
        out.two_pieces = true;
        out.summary.message = both;
        analyse_and_locate_peaks(out, settings, model, eo, equations, ao);
        return out;
      }
      if (dynamic_cast<const NoPeriodicMotion*>(&e) && dynamic_cast<const NoPeriodicMotion*>(&e2))
        throw NoPeriodicMotion(both);
      throw NumericalError(both);
    }
  }
  continuation::Branch first = continuation::trace(equations, start, ao, [&](const continuation::BranchPoint& p) {
    if (progress) progress(p, 0);
  });
  out.points = first.points;
  out.piece.assign(out.points.size(), 0);
  out.summary = first;
  out.summary.points.clear();

  // A branch that cannot reach the end of the range (it turned back through its start, or
  // stalled at a corner) is completed from the other end: a second piece traced backwards
  // from frequency_end_hz until it overlaps the first. It is one curve with the first only if
  // it provably joins it: its last point lies on the first piece (continuation::
  // distance_to_branch). Pieces that do not join but between them cover the range are
  // reported as two separate branches; otherwise the curve stops where the pieces did.
  const double direction = ao.lambda_end > ao.lambda_start ? 1.0 : -1.0;
  double reached = ao.lambda_start;
  for (const auto& p : first.points)
    reached = direction > 0 ? std::max(reached, p.lambda) : std::min(reached, p.lambda);
  if (first.status != continuation::BranchStatus::kReachedEnd &&
      first.status != continuation::BranchStatus::kStartFailed &&
      first.status != continuation::BranchStatus::kMaxPoints) {
    const std::string first_message = first.message;
    say(info, "frf: the branch from " + shortest(ao.lambda_start) + " Hz stopped (" + first.message +
                  ") having reached " + shortest(reached) + " Hz; tracing back from " + shortest(ao.lambda_end) +
                  " Hz");
    continuation::ArclengthOptions back = ao;
    back.lambda_start = ao.lambda_end;
    const double overlap = 4.0 * ao.initial_step * ao.lambda_scale;
    back.lambda_end = direction > 0 ? std::max(ao.lambda_start, reached - overlap)
                                    : std::min(ao.lambda_start, reached + overlap);
    back.max_points = std::max(1, ao.max_points - static_cast<int>(out.points.size()));
    out.two_pieces = true;
    try {
      const Eigen::VectorXd back_start =
          find_start_logged(model, eo, equations, ao, back.lambda_start, out.start_second_piece, info);
      const continuation::Branch second = continuation::trace(equations, back_start, back);
      add_counts(out.summary, second);
      // The range is covered: the curve reaches the end, with this warning.
      auto covered_with = [&](const std::string& warning) {
        out.summary.status = continuation::BranchStatus::kReachedEnd;
        out.summary.message = "";
        out.warnings.push_back(warning);
      };
      // How far towards the start the second piece got.
      double reached_back = ao.lambda_end;
      for (const auto& p : second.points)
        reached_back = direction > 0 ? std::min(reached_back, p.lambda) : std::max(reached_back, p.lambda);
      const bool covered = direction * (reached_back - reached) <= 0;
      // Neither piece got through: a third start in the middle of the gap between where they
      // stopped, traced both ways into them (pieces 2 and 3). The range is covered when both
      // reach the far side of the gap; they are one curve with the others only if each ends
      // on the piece it runs into (the same join test as above).
      std::vector<continuation::Branch> middle;
      std::string middle_message;
      const double f_mid = 0.5 * (reached + reached_back);
      if (!covered && second.status != continuation::BranchStatus::kReachedEnd) {
        const double lo = reached, hi = reached_back;  // the gap, in the direction of travel
        say(info, "frf: the pieces stopped at " + shortest(lo) + " and " + shortest(hi) +
                      " Hz; tracing both ways from " + shortest(f_mid) + " Hz");
        try {
          std::string how_mid;
          const Eigen::VectorXd mid_start = find_start_logged(model, eo, equations, ao, f_mid, how_mid, info);
          const int left = ao.max_points - static_cast<int>(first.points.size() + second.points.size());
          for (int k = 0; k < 2 && left > 2; ++k) {
            continuation::ArclengthOptions mo = ao;
            mo.lambda_start = f_mid;
            mo.lambda_end = k == 0 ? hi + direction * overlap : lo - direction * overlap;
            mo.max_points = std::max(1, left / 2);
            middle.push_back(continuation::trace(equations, mid_start, mo));
            add_counts(out.summary, middle.back());
          }
          if (middle.size() < 2) middle_message = "no points left for the middle of the gap";
        } catch (const NumericalError& e) {
          middle_message = std::string("no start point in the middle of the gap either: ") + e.what();
        }
      }
      const bool middle_covers = middle.size() == 2 && middle[0].status == continuation::BranchStatus::kReachedEnd &&
                                 middle[1].status == continuation::BranchStatus::kReachedEnd;
      if (middle_covers) {
        const double d_second = continuation::distance_to_branch(equations, ao, second.points, middle[0].points.back());
        const double d_first = continuation::distance_to_branch(equations, ao, first.points, middle[1].points.back());
        out.join_distance = std::max(d_first, d_second);
        out.pieces_join = out.join_distance <= kJoinTolerance;
        covered_with(std::string("the curve is in four pieces") +
                     (out.pieces_join ? " that join" : ", not all shown to be one branch") + ": from " +
                     shortest(ao.lambda_start) + " Hz to " + shortest(reached) + " Hz (" + first_message +
                     "), back from " + shortest(ao.lambda_end) + " Hz to " + shortest(reached_back) + " Hz (" +
                     second.message + "), and both ways from " + shortest(f_mid) +
                     " Hz into them (largest join distance " + shortest(out.join_distance) +
                     "; frf.csv column `piece`)");
      } else if (!middle.empty() && extents_cover({&first.points, &second.points, &middle[0].points,
                                                   middle.size() > 1 ? &middle[1].points : nullptr},
                                                  ao.lambda_start, ao.lambda_end)) {
        // The middle pieces turned back (or stopped) too, but every frequency of the range
        // lies between the lowest and highest of some piece, each one continuous path of
        // solutions: reported as pieces not shown to be one branch.
        out.pieces_join = false;
        std::string how;
        for (std::size_t k = 0; k < middle.size(); ++k)
          how += std::string(k == 0 ? "forward" : "; backward") + " from " + shortest(f_mid) +
                 " Hz: " + (middle[k].message.empty() ? std::string("reached its end") : middle[k].message);
        covered_with("the curve is " + std::to_string(2 + middle.size()) +
                     " separate pieces that together cover the range but were not shown to be one branch: from " +
                     shortest(ao.lambda_start) + " Hz to " + shortest(reached) + " Hz (" + first_message +
                     "), back from " + shortest(ao.lambda_end) + " Hz to " + shortest(reached_back) + " Hz (" +
                     second.message + "), " + how + " (frf.csv column `piece`)");
      } else if (second.status == continuation::BranchStatus::kLeftRange && covered) {
        // Both pieces turned back, but between them every frequency of the range has a
        // solution: reported as two separate branches.
        out.pieces_join = false;
        covered_with("the curve is two separate branches: the branch from " + shortest(ao.lambda_start) +
                     " Hz turned back at " + shortest(reached) + " Hz (" + first_message +
                     "), the branch traced back from " + shortest(ao.lambda_end) + " Hz turned back at " +
                     shortest(reached_back) +
                     " Hz; together they cover the range, but they were not shown to be one branch "
                     "(frf.csv column `piece`)");
      } else if (second.status != continuation::BranchStatus::kReachedEnd) {
        out.pieces_join = false;
        out.summary.message =
            first_message + "; tracing back from " + shortest(ao.lambda_end) + " Hz stopped too: " + second.message;
        if (!middle.empty() || !middle_message.empty()) {
          std::string m = middle_message;
          for (std::size_t k = 0; k < middle.size(); ++k)
            if (middle[k].status != continuation::BranchStatus::kReachedEnd)
              m += (m.empty() ? "" : "; ") + std::string(k == 0 ? "forward" : "backward") +
                   " from the middle of the gap: " + middle[k].message;
          out.summary.message += "; " + m;
        }
      } else {
        out.join_distance = continuation::distance_to_branch(equations, ao, first.points, second.points.back());
        // Two solutions of the same equations to tolerance agree far within a step.
        out.pieces_join = out.join_distance <= kJoinTolerance;
        if (out.pieces_join) {
          covered_with("the curve is in two pieces: the branch from " + shortest(ao.lambda_start) + " Hz stopped at " +
                       shortest(reached) + " Hz (" + first_message + "); the rest was traced back from " +
                       shortest(ao.lambda_end) + " Hz and joins it (frf.csv column `piece`)");
        } else {
          // Both pieces are solutions to tolerance and together they cover the range, but
          // they were not shown to be one branch (typically the two stable sides of a fold
          // pair, the unstable branch between them left untraced): reported as two branches.
          covered_with("the curve is two separate branches: the branch from " + shortest(ao.lambda_start) +
                       " Hz stopped at " + shortest(reached) + " Hz (" + first_message +
                       "); the branch traced back from " + shortest(ao.lambda_end) +
                       " Hz covers the rest but does not join it (scaled distance " + shortest(out.join_distance) +
                       "; frf.csv column `piece`)");
        }
      }
      for (const auto& p : second.points) {
        out.points.push_back(p);
        out.piece.push_back(1);
        if (progress) progress(p, 1);
      }
      for (std::size_t k = 0; k < middle.size(); ++k)
        for (const auto& p : middle[k].points) {
          out.points.push_back(p);
          out.piece.push_back(2 + static_cast<int>(k));
          if (progress) progress(p, 2 + static_cast<int>(k));
        }
    } catch (const NumericalError& e) {
      out.summary.message = first_message + "; no start point at the end of the range either: " + e.what();
    }
  }
  hop_if_uncovered(out, model, eo, equations, ao, progress, info);

  analyse_and_locate_peaks(out, settings, model, eo, equations, ao);
  return out;
}

}  // namespace

FrequencyResponse trace_frequency_response(const FrequencyResponseSettings& settings, const ForcedModel& model,
                                           const hbm::ContactEvaluatorOptions& eo, ReducedEquations& equations,
                                           const std::function<void(const continuation::BranchPoint&, int)>& progress,
                                           const Info& info) {
  return trace_from(settings, model, eo, equations, progress, info, true);
}

std::vector<ResponsePeak> distinct_peaks(std::vector<ResponsePeak> peaks, double frequency_unit_hz) {
  // Distinct peaks of a prominence of 2 % cannot be this close; copies measured on the default
  // case at N = 512 were 1.3e-8 Hz and 5e-16 apart, on the paper's preload study (tops
  // sampled at the tracing tolerance) about 1e-6 Hz (2e-6 units) and 1.4e-10 apart: a
  // maximum's frequency is known only to about the square root of its amplitude's precision.
  constexpr double kSamePeakFrequency = 1e-4;  // frequency units
  constexpr double kSamePeakAmplitude = 1e-9;  // relative
  std::stable_sort(peaks.begin(), peaks.end(),
                   [](const ResponsePeak& a, const ResponsePeak& b) { return a.frequency_hz < b.frequency_hz; });
  std::vector<ResponsePeak> distinct;
  for (const ResponsePeak& pk : peaks) {
    const bool copy = std::any_of(distinct.begin(), distinct.end(), [&](const ResponsePeak& q) {
      return q.located && pk.located &&
             std::abs(q.frequency_hz - pk.frequency_hz) <= kSamePeakFrequency * frequency_unit_hz &&
             std::abs(q.amplitude_m - pk.amplitude_m) <= kSamePeakAmplitude * q.amplitude_m;
    });
    if (!copy) distinct.push_back(pk);
  }
  return distinct;
}

std::vector<Eigen::VectorXd> solutions_at_frequency(const FrequencyResponse& response, ReducedEquations& equations,
                                                    double frequency_hz, int* failed) {
  std::vector<Eigen::VectorXd> out;
  if (failed) *failed = 0;
  for (std::size_t i = 0; i + 1 < response.points.size(); ++i) {
    if (response.piece[i] != response.piece[i + 1]) continue;
    const continuation::BranchPoint& a = response.points[i];
    const continuation::BranchPoint& b = response.points[i + 1];
    const bool crosses = (a.lambda - frequency_hz) * (b.lambda - frequency_hz) < 0.0 || b.lambda == frequency_hz ||
                         (i == 0 && a.lambda == frequency_hz);
    if (!crosses) continue;
    const double t = b.lambda == a.lambda ? 0.0 : (frequency_hz - a.lambda) / (b.lambda - a.lambda);
    Eigen::VectorXd x = (1.0 - t) * a.x + t * b.x;
    if (continuation::newton_fixed(equations, x, frequency_hz, response.options) >= 0) out.push_back(std::move(x));
    else if (failed) ++*failed;
  }
  return out;
}

}  // namespace shroudsim::forced
