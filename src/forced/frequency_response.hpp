#pragma once
// The nonlinear frequency response of a forced model (docs/continuation.md, "Frequency
// response"): the continuation's units taken from the problem, the start search, the branch
// traced over the range (completed from the far end when it cannot get through, accepted only
// when the two pieces provably join), the resonance peaks located to solver tolerance, and
// every point analysed. The commands (`frf`, `study`) and the benchmarks call this; they only
// map a case onto it and write what it returns.
//
// Units (so that a model rescaled in time, M -> s^2 M, C -> s C, f -> f / s, gives the same
// curve with the same settings):
//   lambda unit  = |f_end - f_start| / 100             (the range spans 100 units)
//   x unit       = (largest free contact motion over the range, sampled on 41 points and at
//                   every natural frequency of the linear part inside it) / 20
//   initial step = 0.25 units ("auto"), or the Hz-equivalent initial_step_hz / lambda unit,
//                  and never above the largest step, 0.5 units: at least 200 points span the
//                  range.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"
#include "continuation/arclength.hpp"
#include "core/error.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/linear_part.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {

/// A linear part and the parameters of its contact pairs, in the same order.
struct ForcedModel {
  std::unique_ptr<frf::LinearPart> linear;
  std::vector<contact::PairParameters> pairs;
  /// Sector models: the contact pairs and forcing the linear part was built from (for the
  /// operating deflection shapes, frf::sector_displacements); empty for lumped models.
  std::vector<frf::SectorContactPair> sector_pairs;
  std::optional<frf::SectorForcing> sector_forcing;
};

struct FrequencyResponseSettings {
  double frequency_start_hz = 100.0;
  double frequency_end_hz = 220.0;
  double initial_step_hz = 0.0;  ///< Hz-equivalent arclength; <= 0: "auto" (0.25 units)
  int max_points = 5000;
  double tolerance = 1e-8;  ///< Newton tolerance on the scaled residual
  bool locate_peaks = true;
};

/// The range spans this many units of lambda; the free peak this many units of x.
constexpr double kRangeUnits = 100.0;
constexpr double kFreePeakUnits = 20.0;
constexpr double kAutoInitialStep = 0.25;  ///< units
constexpr double kMaxStep = 0.5;           ///< units of lambda per step: at least kRangeUnits / kMaxStep points
constexpr double kMaxArcStep = 20.0;       ///< arclength units per step (a free peak's motion)

/// The largest free contact motion over the range (41 samples and every resonance inside).
double free_motion_peak(const frf::LinearPart& linear, const ReducedEquations& equations, double f_start, double f_end);

/// The continuation options of a forced response (units above).
continuation::ArclengthOptions arclength_options(const FrequencyResponseSettings& settings, const ForcedModel& model,
                                                 const ReducedEquations& equations);

/// The start search's choice of where on a lower harmonic level's homotopy path (points
/// 0..last) the next level's homotopy starts: the index of a point that `serves` (Newton at the
/// new level converges from it), as far along the path as can be found, or -1 when none does.
/// Newton serves at low excitation, where the contact barely slips and the new harmonics are
/// small, and has just failed at the last point (the full excitation); but not on one stretch
/// up to some level: on the 227-pair sector's H = 2 path (86 points) it served from the 21st
/// and 27th points, not from the 28th, 29th, 30th, 32nd and 43rd, and again from the 69th and
/// 71st (the excitation level is not monotone along the path either), so that a bisection from
/// the middle settled at the 27th (the H = 3 path 46 points long, against 15 from the 71st). So the search descends
/// from the end, the gap doubling (the points last - 1, last - 2, last - 4, ..., then 1), and
/// bisects between the first point that serves and the failing one after it. Point 0 (the
/// preload-only state) is never tried.
int last_serving_point(int last, const std::function<bool(int)>& serves);

/// The point of a lower harmonic level's homotopy path (excitation levels `levels`, the last
/// the full excitation `full`, where Newton at the new level has just failed) from which the
/// new level's homotopy starts: the points with 0 < level < full, ranked by level, searched by
/// last_serving_point over the ranks, so that the one found serves at the highest level the
/// search meets; -1 when none does. A homotopy started higher has less of the way to go, and
/// the level is not monotone along a path: on the 227-pair sector's H = 1 path at 104 Hz (129
/// points) it rose to 0.334 at the 44th point, fell back to 0.035 at the 97th and rose to the
/// full level after it; Newton at H = 2 served from the 1st to the 72nd points but for three,
/// and from the 90th to the 102nd. The search along the path found the 102nd (level 0.041);
/// the search by level finds the 44th, in 8 attempts against 10, and the H = 2 path from it
/// is 11 points long against 79 (docs/continuation.md, "Start").
int highest_serving_point(const std::vector<double>& levels, double full, const std::function<bool(int)>& serves);

/// A solution of `equations` at frequency f: Newton from the stuck-contact solution; where it
/// fails (Newton cycling between contact states), from the free response, then harmonic
/// stepping (H = 1, then one harmonic at a time, each new one from zero; a level below H that
/// Newton does not reach is reached by continuation in the excitation level with that many
/// harmonics), then continuation in the excitation level from the preload-only state. When
/// all of these fail at f, the same search a little way off (f (1 +- 0.002, 0.005, 0.01)),
/// then Newton at fixed frequencies back to f. `how` names the method that worked. Throws
/// NumericalError when none does.
Eigen::VectorXd find_start(const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
                           ReducedEquations& equations, const continuation::ArclengthOptions& ao, double f,
                           std::string& how);

/// A resonance peak: a local maximum of the response amplitude along the branch.
struct ResponsePeak {
  double frequency_hz = 0.0;
  double amplitude_m = 0.0;
  std::size_t point = 0;  ///< the sampled point nearest to it (index into points)
  int piece = 0;
  bool located = false;  ///< located to solver tolerance (false: the sampled maximum)
  Eigen::VectorXd x;     ///< the solution (contact motion) there
};

/// The peaks by frequency, each resonance once: two located peaks within 1e-4 frequency units
/// and 1e-9 of each other's amplitude are one peak found twice (a piece that passes over it
/// again after folds, each copy located from its own sampled top); the first is kept. A top
/// passed again is usually not located twice (is_sampled_top).
std::vector<ResponsePeak> distinct_peaks(std::vector<ResponsePeak> peaks, double frequency_unit_hz);

/// Whether `peak`, a maximum located earlier, is the top that the curve samples again at the
/// three points `top` (a sampled maximum in the middle, of amplitude `sampled_amplitude`): a
/// piece that turns back over a top, or two pieces that overlap, pass it twice, and it is
/// located once. True when the peak lies within a quarter of the longer of the two steps from
/// the polyline through the three points, in the scaled variables (x / x_scale,
/// lambda / lambda_scale), and is at least as high as the sampled maximum (to 1e-6 of it: the
/// tracing corrector's precision). A distinct top that close would be one the curve cannot
/// resolve at its own step. This is the geometric pre-filter; analyse_and_locate_peaks then
/// confirms with the corrector (continuation::distance_to_branch) that the peak is a solution
/// of the branch the three points sample.
bool is_sampled_top(const ResponsePeak& peak, const std::array<const continuation::BranchPoint*, 3>& top,
                    double sampled_amplitude, const Eigen::VectorXd& x_scale, double lambda_scale);

struct FrequencyResponse;

/// The solutions of the traced curve at `frequency_hz`: one per crossing of that frequency by
/// a piece (several on an S-shaped stretch), each corrected by Newton at the fixed frequency
/// from the interpolation between the two points around it. Crossings whose Newton fails are
/// left out (failed: how many).
std::vector<Eigen::VectorXd> solutions_at_frequency(const FrequencyResponse& response, ReducedEquations& equations,
                                                    double frequency_hz, int* failed = nullptr);

struct FrequencyResponse {
  std::vector<continuation::BranchPoint> points;  ///< every point, piece after piece
  /// of each point: 0, 1 traced back from the end, 2 and 3 both ways from a gap's middle, then
  /// two per hop past a stopped piece (docs/continuation.md, "Hops past a stopped piece")
  std::vector<int> piece;
  std::vector<PointResult> results;        ///< analyse() of each point
  std::vector<ResponsePeak> peaks;         ///< by frequency
  continuation::Branch summary;            ///< status, message and counts of all pieces (no points)
  continuation::ArclengthOptions options;  ///< as traced (units included)
  std::string start, start_second_piece;   ///< how the start points were found
  bool two_pieces = false;
  bool pieces_join = true;
  double join_distance = 0.0;  ///< scaled distance at the join check
  std::vector<std::string> warnings;
  double peak_seconds = 0.0;  ///< time spent locating peaks
  int polished_points = 0;    ///< points re-solved at their own scale for the energy balance
  int hops = 0;               ///< starts past where pieces stopped (docs/continuation.md, "Hops")
};

/// No start at either end of the range, and at each a time integration from rest (lumped
/// models) settled to a motion that does not repeat every excitation period (subharmonic, or
/// not periodic): the stable steady motion has no harmonic balance of the excitation's period
/// to start from. (An unstable periodic solution may still exist and be reached by a branch
/// from elsewhere; the start search alone cannot find it.)
class NoPeriodicMotion : public NumericalError {
 public:
  using NumericalError::NumericalError;
};

/// The forced response over the range. progress is called for every point that stays on the
/// curve (piece 0, then piece 1 once it is known to join). Throws NumericalError when no start
/// is found (NoPeriodicMotion when time integration shows why); any other failure is in
/// summary.status / summary.message with what was traced.
FrequencyResponse trace_frequency_response(
    const FrequencyResponseSettings& settings, const ForcedModel& model, const hbm::ContactEvaluatorOptions& eo,
    ReducedEquations& equations, const std::function<void(const continuation::BranchPoint&, int piece)>& progress = {},
    const std::function<void(const std::string&)>& info = {});

/// The local maxima of a sequence of amplitudes that stand out: prominence (the drop to the
/// higher of the two lowest points before a higher one, or the curve's end, on each side) at
/// least `min_prominence` times the peak's height. Indices, in order.
std::vector<std::size_t> prominent_maxima(const std::vector<double>& a, double min_prominence);

}  // namespace shroudsim::forced
