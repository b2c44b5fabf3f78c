// Pseudo-arclength continuation against curves known in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "continuation/arclength.hpp"
#include "continuation/events.hpp"

namespace shroudsim::continuation {
namespace {

/// One-harmonic balance of the Duffing oscillator x'' + 2 z x' + x + g x^3 = F cos(w t),
/// x = a cos(w t) + b sin(w t), lambda = w. Its amplitude A obeys the closed form
/// [(1 - w^2 + 3/4 g A^2)^2 + (2 z w)^2] A^2 = F^2, with two folds for a hardening spring.
class Duffing : public ParametricResidual {
 public:
  Duffing(double z, double g, double f) : z_(z), g_(g), f_(f) {}
  int size() const override { return 2; }
  bool has_lambda_derivative() const override { return true; }
  bool evaluate(const Eigen::VectorXd& x, double w, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dl) override {
    const double a = x[0], b = x[1], a2 = a * a + b * b, k = 1 - w * w + 0.75 * g_ * a2;
    r.resize(2);
    r << k * a + 2 * z_ * w * b - f_, k * b - 2 * z_ * w * a;
    if (J) {
      J->resize(2, 2);
      (*J) << k + 1.5 * g_ * a * a, 2 * z_ * w + 1.5 * g_ * a * b, 1.5 * g_ * a * b - 2 * z_ * w, k + 1.5 * g_ * b * b;
    }
    if (dl) {
      dl->resize(2);
      (*dl) << -2 * w * a + 2 * z_ * b, -2 * w * b - 2 * z_ * a;
    }
    return true;
  }
  /// Relative residual of the closed-form amplitude relation.
  double closed_form_error(const BranchPoint& p) const {
    const double a2 = p.x.squaredNorm(), w = p.lambda, k = 1 - w * w + 0.75 * g_ * a2;
    return std::abs((k * k + 4 * z_ * z_ * w * w) * a2 - f_ * f_) / (f_ * f_);
  }

 private:
  double z_, g_, f_;
};

TEST(Arclength, TracesBothFoldsOfTheDuffingResponse) {
  Duffing duffing(/*z=*/0.01, /*g=*/1.0, /*f=*/0.01);
  ArclengthOptions o;
  o.lambda_start = 0.5;
  o.lambda_end = 1.5;
  o.x_scale = Eigen::VectorXd::Constant(2, 0.05);
  o.initial_step = 0.02;
  o.tolerance = 1e-10;
  const Branch b = trace(duffing, Eigen::VectorXd::Zero(2), o);
  ASSERT_EQ(b.status, BranchStatus::kReachedEnd) << b.message;
  EXPECT_EQ(b.turning_points, 2);
  EXPECT_EQ(b.reflections_crossed, 0);  // true folds are not taken for reflections
  EXPECT_DOUBLE_EQ(b.points.back().lambda, 1.5);
  // Newton converged to 1e-10 on residuals of size ~f; the closed form is the same equation
  // squared, so its relative error is of the order tolerance * x_scale / f.
  constexpr double kClosedFormTol = 1e-8;
  double peak = 0.0;
  for (const auto& p : b.points) {
    EXPECT_LT(duffing.closed_form_error(p), kClosedFormTol) << "w = " << p.lambda;
    peak = std::max(peak, p.x.norm());
  }
  // The peak lies on the backbone w^2 = 1 + 3/4 g A^2 with A ~ F / (2 z w): traced, not jumped.
  EXPECT_NEAR(peak, 0.01 / (2 * 0.01 * std::sqrt(1 + 0.75 * peak * peak)), 0.01 * peak);
  // The frequency is not monotonic: it goes back between the folds.
  int reversals = 0;
  for (std::size_t i = 2; i < b.points.size(); ++i) {
    const double d1 = b.points[i - 1].lambda - b.points[i - 2].lambda, d2 = b.points[i].lambda - b.points[i - 1].lambda;
    reversals += d1 * d2 < 0;
  }
  EXPECT_EQ(reversals, 2);
}

/// x^2 + lambda^2 = 1: from (1, 0) the branch turns at lambda = 1 and comes back to 0.
/// x^2 + (lambda - centre)^2 = radius^2.
class Circle : public ParametricResidual {
 public:
  explicit Circle(double centre = 0.0, double radius = 1.0) : centre_(centre), radius_(radius) {}
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, double l, Eigen::VectorXd& r, Eigen::MatrixXd* J, Eigen::VectorXd*) override {
    r = Eigen::VectorXd::Constant(1, x[0] * x[0] + (l - centre_) * (l - centre_) - radius_ * radius_);
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, 2 * x[0]);
    return true;
  }

 private:
  double centre_, radius_;
};

TEST(Arclength, PassesATurningPointAndReportsLeavingTheRange) {
  Circle circle;
  ArclengthOptions o;
  o.lambda_start = 0.0;
  o.lambda_end = 2.0;
  o.initial_step = 0.05;
  const Branch b = trace(circle, Eigen::VectorXd::Constant(1, 0.9), o);
  EXPECT_EQ(b.status, BranchStatus::kLeftRange) << b.message;
  EXPECT_EQ(b.turning_points, 1);
  EXPECT_EQ(b.reflections_crossed, 0);
  EXPECT_NEAR(b.points.front().x[0], 1.0, 1e-8);
  EXPECT_NEAR(b.points.back().x[0], -1.0, 1e-6);
  for (const auto& p : b.points) EXPECT_NEAR(p.x[0] * p.x[0] + p.lambda * p.lambda, 1.0, 1e-7);
  // The turn is an event, located and inserted into the branch: (x, lambda) = (0, 1) to the
  // corrector's tolerance (the residual x^2 + lambda^2 - 1 <= 1e-8 moves lambda by 5e-9 at
  // x = 0; t_lambda is linear in the arclength there, false position locates it).
  int folds = 0;
  for (const auto& p : b.points) {
    if (p.kind != PointKind::kFold) continue;
    ++folds;
    EXPECT_NEAR(p.lambda, 1.0, o.tolerance);
    EXPECT_NEAR(p.x[0], 0.0, 1e-6);
    EXPECT_LT(std::abs(p.tangent[1]), 1e-6);
  }
  EXPECT_EQ(folds, 1);
  EXPECT_EQ(b.smooth_folds, 1);
}

/// x^2 = eps^2 (1 - lambda): a hairpin fold at lambda = 1 whose two sides are 2 eps
/// sqrt(1 - lambda) apart, closer than a quarter of the arclength from the fold (the
/// reflection test's threshold) once 1 - lambda > (8 eps)^2: it is taken for a possible
/// reflection, but nothing lies beyond lambda = 1, so the branch must come back unchanged.
class Hairpin : public ParametricResidual {
 public:
  explicit Hairpin(double eps) : eps_(eps) {}
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, double l, Eigen::VectorXd& r, Eigen::MatrixXd* J, Eigen::VectorXd*) override {
    r = Eigen::VectorXd::Constant(1, x[0] * x[0] - eps_ * eps_ * (1.0 - l));
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, 2 * x[0]);
    return true;
  }

 private:
  double eps_;
};

TEST(Arclength, ANarrowTrueFoldIsKeptWhenNothingLiesBeyondIt) {
  constexpr double kEps = 0.01;
  Hairpin hairpin(kEps);
  ArclengthOptions o;
  o.lambda_start = 0.0;
  o.lambda_end = 2.0;
  // x_scale 1: in scaled units the hairpin is narrow (eps = 0.01).
  o.initial_step = 0.05;
  o.tolerance = 1e-12;
  const Branch b = trace(hairpin, Eigen::VectorXd::Constant(1, kEps), o);
  EXPECT_EQ(b.status, BranchStatus::kLeftRange) << b.message;
  EXPECT_EQ(b.turning_points, 1);
  EXPECT_EQ(b.reflections_crossed, 0);
  EXPECT_NEAR(b.points.back().x[0], -kEps, 1e-9);
  for (const auto& p : b.points) EXPECT_NEAR(p.x[0] * p.x[0], kEps * kEps * (1.0 - p.lambda), 1e-12) << p.lambda;
}

/// x^2 + 1 = 0 has no real solution.
class NoSolution : public ParametricResidual {
 public:
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, double, Eigen::VectorXd& r, Eigen::MatrixXd* J, Eigen::VectorXd*) override {
    r = Eigen::VectorXd::Constant(1, x[0] * x[0] + 1.0);
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, 2 * x[0]);
    return true;
  }
};

TEST(Arclength, ReportsFailuresInsteadOfHidingThem) {
  NoSolution none;
  ArclengthOptions o;
  const Branch b = trace(none, Eigen::VectorXd::Constant(1, 0.3), o);
  EXPECT_EQ(b.status, BranchStatus::kStartFailed);
  EXPECT_TRUE(b.points.empty());
  EXPECT_NE(b.message.find("no solution"), std::string::npos);

  Duffing duffing(0.01, 1.0, 0.01);
  o.lambda_start = 0.5;
  o.lambda_end = 1.5;
  o.x_scale = Eigen::VectorXd::Constant(2, 0.05);  // the scaling of the traced curves above
  o.initial_step = 0.02;
  o.max_points = 7;
  const Branch capped = trace(duffing, Eigen::VectorXd::Zero(2), o);
  EXPECT_EQ(capped.status, BranchStatus::kMaxPoints);
  EXPECT_EQ(capped.points.size(), 7u);
  EXPECT_NE(capped.message.find("max_points"), std::string::npos);
}

TEST(Arclength, FiniteDifferenceInLambdaGivesTheSameCurve) {
  // Without dR/dlambda the solver differentiates in lambda itself; the curve is the same.
  class DuffingNoLambda : public Duffing {
   public:
    using Duffing::Duffing;
    bool has_lambda_derivative() const override { return false; }
  } fd(0.01, 1.0, 0.01);
  Duffing exact(0.01, 1.0, 0.01);
  ArclengthOptions o;
  o.lambda_start = 0.5;
  o.lambda_end = 1.5;
  o.x_scale = Eigen::VectorXd::Constant(2, 0.05);
  o.initial_step = 0.02;
  const Branch a = trace(exact, Eigen::VectorXd::Zero(2), o), b = trace(fd, Eigen::VectorXd::Zero(2), o);
  ASSERT_EQ(b.status, BranchStatus::kReachedEnd);
  EXPECT_EQ(a.turning_points, b.turning_points);
  for (const auto& p : b.points) EXPECT_LT(exact.closed_form_error(p), 1e-6);
}

TEST(Arclength, NoAcceptedStepTurnsTheTangentMoreThanTheLimit) {
  // Coarse steps (unscaled: the peak is ~0.5 high and ~0.02 wide) on the Duffing curve: a
  // corrector that lands far round a bend (or on another stretch of the curve) turns the
  // tangent by more than max_turn_deg; such steps are rejected and halved.
  Duffing duffing(0.01, 1.0, 0.01);
  ArclengthOptions o;
  o.lambda_start = 0.5;
  o.lambda_end = 1.5;
  o.initial_step = 0.5;
  auto max_turn = [](const Branch& b) {
    double worst = 0.0;
    for (std::size_t i = 1; i < b.points.size(); ++i)
      worst = std::max(worst, std::acos(std::clamp(b.points[i].tangent.dot(b.points[i - 1].tangent), -1.0, 1.0)));
    return worst * 180.0 / std::numbers::pi;
  };
  const Branch b = trace(duffing, Eigen::VectorXd::Zero(2), o);
  ASSERT_EQ(b.status, BranchStatus::kReachedEnd) << b.message;
  EXPECT_GT(b.rejected_turns, 0);
  EXPECT_LE(max_turn(b), o.max_turn_deg);
  // With the check off, the same steps do turn it further: the test exercises the check.
  o.max_turn_deg = 179.9;
  EXPECT_GT(max_turn(trace(duffing, Eigen::VectorXd::Zero(2), o)), 30.0);
}

/// x = 3 |lambda - 1|: a corner of 143 degrees, which no hyperplane normal to the incoming
/// tangent meets near the corner.
class Vee : public ParametricResidual {
 public:
  int size() const override { return 1; }
  bool has_lambda_derivative() const override { return true; }
  bool evaluate(const Eigen::VectorXd& x, double l, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dl) override {
    r = Eigen::VectorXd::Constant(1, x[0] - 3.0 * std::abs(l - 1.0));
    if (J) *J = Eigen::MatrixXd::Identity(1, 1);
    if (dl) *dl = Eigen::VectorXd::Constant(1, l > 1.0 ? -3.0 : 3.0);
    return true;
  }
};

TEST(Arclength, ASharpCornerOfANonsmoothBranchIsCrossed) {
  Vee vee;
  ArclengthOptions o;
  o.lambda_start = 0.0;
  o.lambda_end = 2.0;
  o.initial_step = 0.1;
  o.tolerance = 1e-12;
  const Branch b = trace(vee, Eigen::VectorXd::Constant(1, 3.0), o);
  ASSERT_EQ(b.status, BranchStatus::kReachedEnd) << b.message;
  EXPECT_GE(b.kinks_crossed, 1);
  EXPECT_DOUBLE_EQ(b.points.back().lambda, 2.0);
  for (const auto& p : b.points) EXPECT_NEAR(p.x[0], 3.0 * std::abs(p.lambda - 1.0), 1e-10) << p.lambda;
  // Frequency-like parameter: it only moves forward (the corner is not a fold).
  for (std::size_t i = 1; i < b.points.size(); ++i) EXPECT_GT(b.points[i].lambda, b.points[i - 1].lambda);
}

}  // namespace
}  // namespace shroudsim::continuation

namespace shroudsim::continuation {
namespace {

/// The closed-form amplitude relation of Duffing above, G(u, w) = (k^2 + 4 z^2 w^2) u - F^2
/// with u = A^2 and k = 1 - w^2 + 3/4 g u, solved independently of the continuation.
struct DuffingClosedForm {
  double z, g, f;
  /// A fold in w: G = 0 and dG/du = 0, by Newton from (u, w).
  std::pair<double, double> fold_from(double u, double w) const {
    for (int it = 0; it < 50; ++it) {
      const double k = 1 - w * w + 0.75 * g * u;
      const double G = (k * k + 4 * z * z * w * w) * u - f * f;
      const double H = k * k + 4 * z * z * w * w + 1.5 * g * u * k;  // dG/du
      const double Gw = (-4 * w * k + 8 * z * z * w) * u;
      const double Hu = 3 * g * k + 1.125 * g * g * u, Hw = -4 * w * k + 8 * z * z * w - 3 * g * u * w;
      const double det = H * Hw - Gw * Hu;
      const double du = -(G * Hw - Gw * H) / det, dw = -(H * H - Hu * G) / det;
      u += du;
      w += dw;
      if (std::abs(du) < 1e-16 * u && std::abs(dw) < 1e-16 * w) break;
    }
    return {u, w};
  }
  /// The largest amplitude along the curve: dG/dw = 0 gives k = 2 z^2, then G = 0 in u alone.
  double peak_amplitude() const {
    auto G = [&](double u) { return (4 * std::pow(z, 4) + 4 * z * z * (1 + 0.75 * g * u - 2 * z * z)) * u - f * f; };
    double lo = 0.0, hi = 10.0;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (G(mid) > 0 ? hi : lo) = mid;
    }
    return std::sqrt(0.5 * (lo + hi));
  }
};

ArclengthOptions duffing_options(double step) {
  ArclengthOptions o;
  o.lambda_start = 0.5;
  o.lambda_end = 1.5;
  o.x_scale = Eigen::VectorXd::Constant(2, 0.05);
  o.initial_step = step;
  o.tolerance = 1e-12;
  return o;
}

TEST(ArclengthEvents, DuffingFoldsAreLocatedToTheClosedForm) {
  Duffing duffing(0.01, 1.0, 0.01);
  const DuffingClosedForm exact{0.01, 1.0, 0.01};
  const Branch b = trace(duffing, Eigen::VectorXd::Zero(2), duffing_options(0.02));
  ASSERT_EQ(b.status, BranchStatus::kReachedEnd) << b.message;
  int folds = 0;
  for (const auto& p : b.points) {
    if (p.kind != PointKind::kFold) continue;
    ++folds;
    const auto [u, w] = exact.fold_from(p.x.squaredNorm(), p.lambda);
    // lambda at the fold to 1e-8 relative (the goal): the fold is a quadratic
    // extremum of lambda along the branch, so a located arclength error e moves lambda by
    // ~ curvature * e^2.
    EXPECT_NEAR(p.lambda, w, 1e-8 * w);
    EXPECT_NEAR(p.x.squaredNorm(), u, 1e-5 * u);
  }
  EXPECT_EQ(folds, 2);
  EXPECT_EQ(b.smooth_folds, 2);
}

TEST(ArclengthEvents, PeakLocationDoesNotDependOnTheStep) {
  Duffing duffing(0.01, 1.0, 0.01);
  const double exact = DuffingClosedForm{0.01, 1.0, 0.01}.peak_amplitude();
  auto amplitude = [](const Eigen::VectorXd& x, double) { return x.norm(); };
  std::vector<double> located;
  for (double step : {0.005, 0.02, 0.08}) {
    const ArclengthOptions o = duffing_options(step);
    const Branch b = trace(duffing, Eigen::VectorXd::Zero(2), o);
    ASSERT_EQ(b.status, BranchStatus::kReachedEnd) << b.message;
    std::size_t k = 0;
    for (std::size_t i = 0; i < b.points.size(); ++i)
      if (b.points[i].x.norm() > b.points[k].x.norm()) k = i;
    ASSERT_GT(k, 0u);
    ASSERT_LT(k + 1, b.points.size());
    double best = b.points[k].x.norm();
    const double sampled = best;
    for (std::size_t from : {k - 1, k}) {
      const BranchPoint& p = b.points[from];
      const BranchPoint& q = b.points[from + 1];
      Eigen::VectorXd dy(3);
      dy << (q.x - p.x) / 0.05, q.lambda - p.lambda;
      const Extremum e = locate_maximum(duffing, o, p, p.tangent.dot(dy), amplitude);
      if (e.found) best = std::max(best, e.value);
    }
    // The sampled maximum is off by the square of the distance to the peak; the located one
    // only by the corrector's tolerance.
    EXPECT_NEAR(best, exact, 1e-9 * exact) << "step " << step << ", sampled " << sampled;
    located.push_back(best);
  }
  EXPECT_NEAR(located[0], located[2], 1e-9 * located[0]);
}

TEST(ArclengthEvents, InvalidOptionsAreRefusedOnEntry) {
  Duffing duffing(0.01, 1.0, 0.01);
  ArclengthOptions o = duffing_options(0.02);
  o.x_scale = Eigen::VectorXd::Constant(3, 0.05);  // the residual has 2 unknowns
  EXPECT_THROW(trace(duffing, Eigen::VectorXd::Zero(2), o), std::invalid_argument);
  o = duffing_options(0.02);
  EXPECT_THROW(trace(duffing, Eigen::VectorXd::Zero(3), o), std::invalid_argument);
  o.lambda_scale = 0.0;
  EXPECT_THROW(trace(duffing, Eigen::VectorXd::Zero(2), o), std::invalid_argument);
  o = duffing_options(0.02);
  o.residual_scale = Eigen::VectorXd::Constant(2, std::nan(""));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  EXPECT_THROW(newton_fixed(duffing, x, 0.5, o), std::invalid_argument);
}

/// (x - lambda)(x - lambda - d) = 0: two parallel branches a distance d apart in x, like the
/// twins a sampled friction law makes.
class Twins : public ParametricResidual {
 public:
  explicit Twins(double d) : d_(d) {}
  int size() const override { return 1; }
  bool evaluate(const Eigen::VectorXd& x, double l, Eigen::VectorXd& r, Eigen::MatrixXd* J, Eigen::VectorXd*) override {
    const double a = x[0] - l, b = x[0] - l - d_;
    r = Eigen::VectorXd::Constant(1, a * b);
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, a + b);
    return true;
  }

 private:
  double d_;
};

TEST(ArclengthEvents, APieceJoinsItsOwnBranchAndNotATwin) {
  Twins twins(1e-3);
  ArclengthOptions o;
  o.lambda_start = 0.0;
  o.lambda_end = 1.0;
  o.initial_step = 0.05;
  o.tolerance = 1e-12;
  const Branch lower = trace(twins, Eigen::VectorXd::Constant(1, 0.0), o);
  ASSERT_EQ(lower.status, BranchStatus::kReachedEnd);
  // Traced back from the end on the same branch: joins.
  ArclengthOptions back = o;
  back.lambda_start = 1.0;
  back.lambda_end = 0.4;
  const Branch same = trace(twins, Eigen::VectorXd::Constant(1, 1.0), back);
  ASSERT_EQ(same.status, BranchStatus::kReachedEnd);
  EXPECT_LT(distance_to_branch(twins, o, lower.points, same.points.back()), 1e-9);
  // From the end on the twin: the twin's point lies 1e-3 / sqrt(2) off the first branch.
  const Branch twin = trace(twins, Eigen::VectorXd::Constant(1, 1.0 + 1e-3), back);
  ASSERT_EQ(twin.status, BranchStatus::kReachedEnd);
  EXPECT_NEAR(distance_to_branch(twins, o, lower.points, twin.points.back()), 1e-3 / std::sqrt(2.0), 1e-6);
}

}  // namespace
}  // namespace shroudsim::continuation

namespace shroudsim::continuation {
namespace {

/// lambda = phi(x), phi piecewise linear with a Z: slope 1 up to x = 1, slope -a over
/// (1, 1 + w), slope 1 again beyond. At x = 1 the branch turns back in lambda by
/// 180 - 45 - atan(1/a) degrees: past the corner no hyperplane normal to the incoming tangent
/// meets the middle piece, only the piece beyond it.
class Zee : public ParametricResidual {
 public:
  static constexpr double a = 20.0, w = 0.05;
  static double phi(double x) {
    if (x < 1.0) return x;
    if (x < 1.0 + w) return 1.0 - a * (x - 1.0);
    return 1.0 - a * w + (x - 1.0 - w);
  }
  int size() const override { return 1; }
  bool has_lambda_derivative() const override { return true; }
  bool evaluate(const Eigen::VectorXd& x, double l, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dl) override {
    const double s = x[0] < 1.0 ? 1.0 : x[0] < 1.0 + w ? -a : 1.0;
    r = Eigen::VectorXd::Constant(1, l - phi(x[0]));
    if (J) *J = Eigen::MatrixXd::Constant(1, 1, -s);
    if (dl) *dl = Eigen::VectorXd::Constant(1, 1.0);
    return true;
  }
};

TEST(ArclengthEvents, ACornerThatTurnsTheBranchBackIsFollowedOntoTheOtherPiece) {
  Zee zee;
  ArclengthOptions o;
  o.lambda_start = 0.0;
  o.lambda_end = 2.0;
  o.tolerance = 1e-12;
  int evaluations = 0;
  ScaledSystem s(zee, o, &evaluations);
  const Eigen::VectorXd y = s.to_scaled(Eigen::VectorXd::Constant(1, 0.999), 0.999);
  const Eigen::VectorXd t = Eigen::Vector2d(1.0, 1.0).normalized();  // along the first piece
  Eigen::VectorXd y_new, t_new;
  int iterations = 0;
  double rnorm = 0.0;
  ASSERT_TRUE(turn_at_corner(s, y, t, 0.01, y_new, t_new, iterations, rnorm));
  // On the middle piece: a solution with 1 < x < 1 + w, heading along it (x up, lambda down).
  const double x = y_new[0], l = y_new[1];
  EXPECT_GT(x, 1.0);
  EXPECT_LT(x, 1.0 + Zee::w);
  EXPECT_NEAR(l, Zee::phi(x), 1e-12);
  const Eigen::Vector2d middle = Eigen::Vector2d(1.0, -Zee::a).normalized();
  EXPECT_NEAR(t_new.dot(middle), 1.0, 1e-12);
  // The residual gives no continuation beyond the first piece's own end when nothing turns:
  // on a straight piece the residual never leaves zero within reach.
  const Eigen::VectorXd y0 = s.to_scaled(Eigen::VectorXd::Constant(1, 0.5), 0.5);
  EXPECT_FALSE(turn_at_corner(s, y0, t, 0.01, y_new, t_new, iterations, rnorm));
}

TEST(Arclength, AClosedBranchIsReportedOnceItComesBackOntoItself) {
  // x^2 + (lambda - 0.5)^2 = 0.09: a closed branch (an isola) inside the range once the
  // branch may go below lambda_start.
  Circle isola(0.5, 0.3);
  ArclengthOptions o;
  o.lambda_start = 0.3;
  o.lambda_end = 1.0;
  o.start_slack = 0.5;
  o.initial_step = 0.02;
  const Branch b = trace(isola, Eigen::VectorXd::Constant(1, 0.2), o);
  ASSERT_EQ(b.status, BranchStatus::kClosedLoop) << b.message;
  EXPECT_EQ(b.turning_points, 2);
  for (const auto& p : b.points) EXPECT_NEAR(p.x[0] * p.x[0] + (p.lambda - 0.5) * (p.lambda - 0.5), 0.09, 1e-7);
  // One lap: the arclength travelled is the circumference, 2 pi 0.3, to within a few steps.
  double arc = 0.0, largest = 0.0;
  for (std::size_t i = 1; i < b.points.size(); ++i) {
    const double chord =
        std::hypot(b.points[i].x[0] - b.points[i - 1].x[0], b.points[i].lambda - b.points[i - 1].lambda);
    arc += chord;
    largest = std::max(largest, chord);
  }
  const double lap = 2 * std::numbers::pi * 0.3;
  EXPECT_GT(arc, lap * 0.98);
  EXPECT_LT(arc, lap + 2 * largest);
}

}  // namespace
}  // namespace shroudsim::continuation
