#include "contact/contact_law.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"

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

int n_directions(Model model) {
  return (model == Model::one_d || model == Model::one_d_exact) ? 1 : 3;
}

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
  const double kt = tangential_stiffness, kn = normal_stiffness, mu = friction_coefficient,
               n0 = normal_preload;
  require(std::isfinite(kt) && kt > 0.0,
          "tangential_stiffness = " + num(kt) + " violates: tangential_stiffness > 0 (finite)",
          errors, &valid);
  if (n_directions(model) == 3) {
    require(std::isfinite(kn) && kn > 0.0,
            "normal_stiffness = " + num(kn) + " violates: normal_stiffness > 0 (finite)", errors,
            &valid);
  }
  require(std::isfinite(mu) && mu >= 0.0,
          "friction_coefficient = " + num(mu) + " violates: friction_coefficient >= 0 (finite)",
          errors, &valid);
  require(std::isfinite(n0), "normal_preload = " + num(n0) + " violates: finite", errors, &valid);
  if (n_directions(model) == 1) {
    require(!(n0 < 0.0),
            "normal_preload = " + num(n0) + " violates: normal_preload >= 0 for model " +
                to_string(model) + " (constant normal load, no gap)",
            errors, &valid);
  }
  return valid;
}

bool LawOptions::validate(std::vector<std::string>* errors) const {
  bool valid = true;
  require(max_periods >= 1, "max_periods = " + std::to_string(max_periods) + " violates: >= 1",
          errors, &valid);
  require(std::isfinite(period_tolerance) && period_tolerance > 0.0 && period_tolerance <= 1e-3,
          "period_tolerance = " + num(period_tolerance) + " violates: 0 < period_tolerance <= 1e-3",
          errors, &valid);
  return valid;
}

// ---------------------------------------------------------------------------------------
// exact_linear step. Written once as a template and evaluated either in double or in a
// forward-mode dual number carrying the 6 partial derivatives (e0x, e0y, dwx, dwy, a0, a1):
// the exact derivative of the step (every branch is decided on values, as in the map).
namespace {

constexpr int kNd = 6;  // partials: e0x, e0y, dwx, dwy, a0, a1

struct Dual {
  double v = 0.0;
  std::array<double, kNd> g{};
  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants promote
};

inline double val(double x) { return x; }
inline double val(const Dual& x) { return x.v; }

// f(x) with f(x.v) = value and f'(x.v) = slope.
inline Dual unary(const Dual& x, double value, double slope) {
  Dual r(value);
  for (int i = 0; i < kNd; ++i) r.g[i] = slope * x.g[i];
  return r;
}

inline Dual operator+(const Dual& a, const Dual& b) {
  Dual r(a.v + b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] + b.g[i];
  return r;
}
inline Dual operator-(const Dual& a, const Dual& b) {
  Dual r(a.v - b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] - b.g[i];
  return r;
}
inline Dual operator-(const Dual& a) { return unary(a, -a.v, -1.0); }
inline Dual operator*(const Dual& a, const Dual& b) {
  Dual r(a.v * b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] * b.v + a.v * b.g[i];
  return r;
}
inline Dual operator/(const Dual& a, const Dual& b) {
  const double q = a.v / b.v;
  Dual r(q);
  for (int i = 0; i < kNd; ++i) r.g[i] = (a.g[i] - q * b.g[i]) / b.v;
  return r;
}
inline Dual operator+(const Dual& a, double b) { return a + Dual(b); }
inline Dual operator-(double a, const Dual& b) { return Dual(a) - b; }
inline Dual operator*(double a, const Dual& b) { return unary(b, a * b.v, a); }
inline Dual operator/(const Dual& a, double b) { return unary(a, a.v / b, 1.0 / b); }

inline Dual sqrt(const Dual& x) {
  const double s = std::sqrt(x.v);
  return unary(x, s, 0.5 / s);
}
inline Dual exp(const Dual& x) {
  const double e = std::exp(x.v);
  return unary(x, e, e);
}
inline Dual log(const Dual& x) { return unary(x, std::log(x.v), 1.0 / x.v); }
inline Dual operator+(double a, const Dual& b) { return Dual(a) + b; }

using std::exp;
using std::log;
using std::sqrt;

// ln(1 + y)/y, smooth through y = 0 (dual-number friendly).
template <class S>
S log1p_over(const S& y) {
  if (std::abs(val(y)) < 1e-6) return 1.0 - y / 2.0 + y * y / 3.0;
  return log(1.0 + y) / y;
}

// One step with w_t and the slip radius a(s) = a0 + s (a1 - a0) linear in s in [0, 1]:
//  stick while |e0 + s dw| < a(s): first crossing s* from the quadratic
//    g(s) = |e0 + s dw|^2 - a(s)^2 = A s^2 + 2 B s + C,  A = |dw|^2 - da^2,
//    B = e0.dw - a0 da,  C = |e0|^2 - a0^2 <= 0;
//  then slip on the circle: with phi = q - p (q = arg dw, p = arg e),
//    a dp/ds = |dw| sin(phi)  =>  tan(phi1/2) = tan(phi0/2) exp(-K),
//    K = |dw| int_{s*}^1 ds/a(s) = |dw| (1 - s*)/a(s*) * ln(1 + y)/y,  y = (1 - s*) da/a(s*),
//  and slip persists once started (g'(s*) >= 0 means dw.e >= a da, and cos(phi) grows).
template <class S>
void exact_linear_step_t(S e0x, S e0y, const S& dwx, const S& dwy, const S& a0, const S& a1,
                         S& e1x, S& e1y, bool& stuck) {
  stuck = false;
  // Start state inside the start circle (it is, up to round-off, by construction).
  const S n0sq = e0x * e0x + e0y * e0y;
  bool projected = false;
  if (val(n0sq) > val(a0) * val(a0)) {
    const S n0 = sqrt(n0sq);
    e0x = a0 * e0x / n0;
    e0y = a0 * e0y / n0;
    projected = true;
  }
  const S dwsq = dwx * dwx + dwy * dwy;
  if (!(val(dwsq) > 0.0)) {  // no tangential motion: stick (|e0| <= a0 <= ... see a1 check)
    e1x = e0x;
    e1y = e0y;
    const S n1sq = e1x * e1x + e1y * e1y;
    if (val(n1sq) > val(a1) * val(a1)) {
      const S n1 = sqrt(n1sq);
      e1x = a1 * e1x / n1;
      e1y = a1 * e1y / n1;
    }
    return;
  }
  const S da = a1 - a0;
  const S A = dwsq - da * da;
  const S B = e0x * dwx + e0y * dwy - a0 * da;
  const S C = e0x * e0x + e0y * e0y - a0 * a0;
  const S disc = B * B - A * C;
  bool crosses = false;
  S s(0.0);
  if (val(B) > 0.0) {
    if (val(disc) >= 0.0) {
      crosses = true;
      const S root = val(disc) > 0.0 ? sqrt(disc) : S(0.0);
      s = (-C) / (B + root);
    }
  } else if (val(A) > 0.0) {
    crosses = true;
    const S root = val(disc) > 0.0 ? sqrt(disc) : S(0.0);
    s = (root - B) / A;
  }
  if (!crosses || val(s) >= 1.0) {  // stick over the whole step
    e1x = e0x + dwx;
    e1y = e0y + dwy;
    stuck = !projected;
    return;
  }
  // Trigonometry-free: unit vectors q^ = dw/|dw|, u = e(s*)/|e(s*)|, cos/sin of phi0 from
  // dot/cross products, tan(phi/2) by the half-angle identities.
  const S dwn = sqrt(dwsq);
  const S qx = dwx / dwn, qy = dwy / dwn;
  const S as = a0 + s * da;  // radius at the onset of slip
  if (!(val(as) > 0.0)) {    // contact closing at this instant: force along the motion
    e1x = a1 * qx;
    e1y = a1 * qy;
    return;
  }
  const S esx = e0x + s * dwx;
  const S esy = e0y + s * dwy;
  const S esn = sqrt(esx * esx + esy * esy);
  const S ux = esx / esn, uy = esy / esn;
  const S c0 = qx * ux + qy * uy;  // cos(phi0)
  const S s0 = qy * ux - qx * uy;  // sin(phi0), phi0 = q - p0
  if (val(c0) <= -0.5 && val(s0) == 0.0) {  // phi0 = pi: stays opposite to the motion
    e1x = -(a1 * qx);
    e1y = -(a1 * qy);
    return;
  }
  const S t0 = val(c0) > -0.5 ? s0 / (1.0 + c0) : (1.0 - c0) / s0;  // tan(phi0/2)
  const S r = 1.0 - s;
  const S kappa = r * dwn / as * log1p_over(r * da / as);
  const S t1 = t0 * exp(-kappa);  // tan(phi1/2)
  S c1, s1;
  if (std::abs(val(t1)) <= 1.0) {
    const S den = 1.0 + t1 * t1;
    c1 = (1.0 - t1 * t1) / den;
    s1 = 2.0 * t1 / den;
  } else {
    const S v = 1.0 / t1;
    const S den = v * v + 1.0;
    c1 = (v * v - 1.0) / den;
    s1 = 2.0 * v / den;
  }
  // e1 = a1 (cos p1, sin p1), p1 = q - phi1.
  e1x = a1 * (qx * c1 + qy * s1);
  e1y = a1 * (qy * c1 - qx * s1);
}

inline Dual seed(double value, int index) {
  Dual r(value);
  r.g[index] = 1.0;
  return r;
}

}  // namespace

Eigen::Vector2d exact_linear_step(const Eigen::Vector2d& e0, const Eigen::Vector2d& dw, double a,
                                  double a_end, Eigen::Matrix<double, 2, 6>* jac, bool* stuck) {
  bool stuck_local = false;
  bool& st = stuck ? *stuck : stuck_local;
  SHROUDSIM_ASSERT(a >= 0.0 && a_end > 0.0, "exact_linear_step needs a0 >= 0, a1 > 0");
  if (jac == nullptr) {
    double e1x = 0.0, e1y = 0.0;
    exact_linear_step_t<double>(e0.x(), e0.y(), dw.x(), dw.y(), a, a_end, e1x, e1y, st);
    return {e1x, e1y};
  }
  Dual e1x, e1y;
  exact_linear_step_t<Dual>(seed(e0.x(), 0), seed(e0.y(), 1), seed(dw.x(), 2), seed(dw.y(), 3),
                          seed(a, 4), seed(a_end, 5), e1x, e1y, st);
  for (int i = 0; i < kNd; ++i) {
    (*jac)(0, i) = e1x.g[i];
    (*jac)(1, i) = e1y.g[i];
  }
  return {e1x.v, e1y.v};
}

// ---------------------------------------------------------------------------------------

PeriodicLaw::PeriodicLaw(LawOptions options) : options_(options) {
  std::vector<std::string> errors;
  if (!options_.validate(&errors)) throw std::invalid_argument("contact::LawOptions: " + errors[0]);
  if (options_.model == Model::one_d_exact)
    throw std::invalid_argument(
        "contact::PeriodicLaw: model 1d_exact is time-continuous (use jenkins_single_harmonic)");
}

PeriodicStatus PeriodicLaw::evaluate(const PairParameters& pair, const Eigen::MatrixX3d& w,
                                     Eigen::MatrixX3d& f, const Eigen::MatrixXd* basis,
                                     LinearizedPeriod* lin) {
  SHROUDSIM_CHECK((basis == nullptr) == (lin == nullptr), "basis and lin go together");
  SHROUDSIM_CHECK(w.rows() >= 1, "at least one sample");
  if (basis != nullptr) {
    SHROUDSIM_CHECK(basis->rows() == w.rows(), "basis rows = time samples");
    return run<true>(pair, w, f, basis, lin);
  }
  return run<false>(pair, w, f, nullptr, nullptr);
}

void LinearizedPeriod::expand(const Eigen::MatrixXd& basis, std::array<RowMatrix, 3>& df) const {
  const int n = static_cast<int>(basis.rows());
  const int m = static_cast<int>(basis.cols());
  for (auto& d : df) d.setZero(n, p);
  for (int i = 0; i < 2; ++i) {
    for (size_t r = 0; r < runs[i].size(); ++r) {
      const Run& run = runs[i][r];
      for (int l = run.first; l <= run.last; ++l) {
        if (run.anchor < 0) {
          df[i].row(l) = -kt * run_x[i].row(static_cast<Eigen::Index>(r));
        } else {
          df[i].row(l).segment(i * m, m) = -kt * run.alpha * basis.row(run.anchor);
          if (run.beta != 0.0) df[i].row(l).segment(2 * m, m) = -kt * run.beta * basis.row(run.anchor);
        }
        df[i].row(l).segment(i * m, m) += kt * basis.row(l);
      }
    }
    for (size_t l = 0; l < slip_weight[i].size(); ++l)
      if (slip_weight[i][l] != 0.0) df[i].row(static_cast<Eigen::Index>(l)).segment(2 * m, m) = slip_weight[i][l] * basis.row(static_cast<Eigen::Index>(l));
    for (size_t k = 0; k < dense_index[i].size(); ++k)
      df[i].row(dense_index[i][k]) = dense[i].row(static_cast<Eigen::Index>(k));
  }
  for (int l = 0; l < n; ++l)
    if (!pressed.empty() && pressed[l]) df[2].row(l).segment(2 * m, m) = kn * basis.row(l);
}

namespace {
// Pseudo-inverse of A = I - Phi_d (2 x 2). Phi_d is a product of per-sample maps: 0 at
// separation, a contraction at slip, the identity in stick, and exactly neutral directions
// (eigenvalue 1: a family of periodic states, e.g. a static tangential load at the slip
// limit, or pure stick) appear as singular values of A at the round-off of that product
// (~1e-13 for a few hundred samples). Those directions are dropped (d* held along them, as
// d = 0 is kept in pure stick); kSingular sits well above that round-off and far below any
// contraction the iteration resolves (1 - lambda = 1e-10 would need ~1e11 plain periods).
constexpr double kSingular = 1e-10;
// Plain periods before the Newton iteration of the coupled model starts (see run()).
constexpr int kPlainPeriods = 4;
bool pseudo_inverse2(const Eigen::Matrix2d& a, Eigen::Matrix2d& inv) {
  if (!a.allFinite()) return false;
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector2d sv = svd.singularValues();
  Eigen::Vector2d si = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i)
    if (sv(i) > kSingular) si(i) = 1.0 / sv(i);
  if (si.isZero(0.0)) return false;
  inv = svd.matrixV() * si.asDiagonal() * svd.matrixU().transpose();
  return inv.allFinite();
}
}  // namespace

template <bool kD>
PeriodicStatus PeriodicLaw::run(const PairParameters& pair, const Eigen::MatrixX3d& w,
                                Eigen::MatrixX3d& f, const Eigen::MatrixXd* basis,
                                LinearizedPeriod* lin) {
  const int n = static_cast<int>(w.rows());
  const Model model = options_.model;
  const bool two_d = model != Model::one_d;
  const bool has_normal = model != Model::one_d;
  const bool coupled = model == Model::full3d;

  const int m = kD ? static_cast<int>(basis->cols()) : 0;
  const int p = n_directions(model) * m;

  double wmax = 0.0;
  for (int l = 0; l < n; ++l) {
    wmax = std::max(wmax, std::abs(w(l, 0)));
    if (two_d) wmax = std::max(wmax, std::abs(w(l, 1)));
  }
  const double tol = options_.period_tolerance * wmax;

  f.setZero(n, 3);
  if constexpr (kD) {
    xd_.setZero(p);
    yd_.setZero(p);
    lin->kt = pair.tangential_stiffness;
    lin->kn = has_normal ? pair.normal_stiffness : 0.0;
    lin->p = p;
    const int nd = two_d ? 2 : 1;
    for (int i = 0; i < 2; ++i) {
      const int rows = i < nd ? n : 0;
      if (lin->run_x[i].rows() != rows || lin->run_x[i].cols() != p) lin->run_x[i].resize(rows, p);
      if (lin->dense[i].rows() != rows || lin->dense[i].cols() != p) lin->dense[i].resize(rows, p);
      lin->runs[i].reserve(n);
      lin->dense_index[i].reserve(n);
    }
    lin->pressed.assign(n, 0);
  }
  d_ = {0.0, 0.0};  // damper position [m], starts at 0
  anchor_ = {};
  PeriodicStatus status;
  status.converged = false;
  auto change = [](const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return std::max(std::abs(a[0] - b[0]), std::abs(a[1] - b[1]));
  };

  if (!coupled) {
    // Uncoupled models: plain repetition (memoryless slip: 2 periods typically), the
    // derivative carried through all periods by the anchors.
    for (int k = 1; k <= options_.max_periods; ++k) {
      const std::array<double, 2> d_start = d_;
      period<kD>(pair, w, f, basis, lin, false);
      status.periods = k;
      if (change(d_, d_start) <= tol) {
        status.converged = true;
        break;
      }
    }
    return status;
  }

  // Coupled model. First plain repetition from d = 0 for up to kPlainPeriods periods (with
  // the derivative carried through them, as for the uncoupled models): most states repeat
  // within 2 to 4 periods, at the cost they had before.
  for (int k = 1; k <= std::min(kPlainPeriods, options_.max_periods); ++k) {
    const std::array<double, 2> d_start = d_;
    last_start_ = d_start;
    period<kD>(pair, w, f, basis, lin, false);
    status.periods = k;
    if (change(d_, d_start) <= tol) {
      status.converged = true;
      return status;
    }
  }
  // Slow repetition (a weak contraction, e.g. a static tangential load at the slip limit with
  // a small oscillation: ~0.998 per period): safeguarded Newton on g(d) = Phi(d) - d from where
  // the plain periods ended, forces-only periods carrying Phi_d. A Newton step is accepted
  // when it reduces max|g| (Phi is strongly curved far from d*: the first steps reduce |g| by
  // ~2, the last ones quadratically), else the plain repetition d <- Phi(d) is taken.
  std::array<double, 2> dk{0.0, 0.0};  // accepted iterate
  auto pass = [&](const std::array<double, 2>& start) {
    d_ = start;
    period<false>(pair, w, f, nullptr, nullptr, true);
    ++status.periods;
    return std::array<double, 2>{d_[0] - start[0], d_[1] - start[1]};  // g(start)
  };
  // From where the plain periods ended (unless the cap is reached already).
  dk = d_;
  std::array<double, 2> g{};
  double gn = 0.0;
  Eigen::Matrix2d jk = Eigen::Matrix2d::Identity();
  bool slipped = false;
  if (status.periods < options_.max_periods) {
    g = pass(dk);
    gn = std::max(std::abs(g[0]), std::abs(g[1]));
    jk = dd_start_;
    slipped = slipped_;
  } else {
    gn = change(d_, last_start_);
    dk = last_start_;
  }
  while (!(gn <= tol) && status.periods < options_.max_periods) {
    if (slipped) {
      // Newton: g(dk + delta) ~ g + (Phi_d - I) delta = 0.
      Eigen::Matrix2d ai;
      if (pseudo_inverse2(Eigen::Matrix2d::Identity() - jk, ai)) {
        const Eigen::Vector2d delta = ai * Eigen::Vector2d(g[0], g[1]);
        const std::array<double, 2> trial{dk[0] + delta.x(), dk[1] + delta.y()};
        if (std::isfinite(trial[0]) && std::isfinite(trial[1]) && (delta.x() != 0.0 || delta.y() != 0.0)) {
          const std::array<double, 2> gt = pass(trial);
          const double gtn = std::max(std::abs(gt[0]), std::abs(gt[1]));
          if (gtn <= tol || gtn < gn) {  // accepted
            dk = trial;
            g = gt;
            gn = gtn;
            jk = dd_start_;
            slipped = slipped_;
            continue;
          }
          if (status.periods >= options_.max_periods) break;
        }
      }
    }
    // Safeguard: plain repetition, dk <- Phi(dk) = dk + g.
    dk = {dk[0] + g[0], dk[1] + g[1]};
    g = pass(dk);
    gn = std::max(std::abs(g[0]), std::abs(g[1]));
    jk = dd_start_;
    slipped = slipped_;
  }
  status.converged = gn <= tol;
  if constexpr (kD) {
    // The returned period once more from dk with the derivative, at fixed d_start
    // (xd_ = yd_ = 0), carrying the sensitivities to d_start; then add the term through
    // dd*/dc = (I - Phi_d)^{-1} Phi_c.
    d_ = dk;
    xd_.setZero();
    yd_.setZero();
    period<true>(pair, w, f, basis, lin, true);
    Eigen::Matrix2d ai;
    fixed_point_dc_.resize(2, p);
    if (slipped_ && pseudo_inverse2(Eigen::Matrix2d::Identity() - dd_start_, ai)) {
      fixed_point_dc_.row(0) = ai(0, 0) * xd_ + ai(0, 1) * yd_;
      fixed_point_dc_.row(1) = ai(1, 0) * xd_ + ai(1, 1) * yd_;
    } else {
      fixed_point_dc_.setZero();  // pure stick: d* held (see the header)
    }
    if (!fixed_point_dc_.isZero(0.0)) {
      const auto z0 = fixed_point_dc_.row(0);
      const auto z1 = fixed_point_dc_.row(1);
      for (int i = 0; i < 2; ++i) {
        for (size_t r = 0; r < lin->runs[i].size(); ++r) {
          const Eigen::Matrix2d& s = run_d_[i][r];
          lin->run_x[i].row(static_cast<Eigen::Index>(r)) += s(i, 0) * z0 + s(i, 1) * z1;
        }
        for (size_t k = 0; k < lin->dense_index[i].size(); ++k) {
          const Eigen::Matrix2d& q = dense_q_[k];
          lin->dense[i].row(static_cast<Eigen::Index>(k)) += q(i, 0) * z0 + q(i, 1) * z1;
        }
      }
    }
  }
  return status;
}

template <bool kD>
void PeriodicLaw::period(const PairParameters& pair, const Eigen::MatrixX3d& w,
                         Eigen::MatrixX3d& f, const Eigen::MatrixXd* basis,
                         LinearizedPeriod* lin, bool track) {
  const int n = static_cast<int>(w.rows());
  const Model model = options_.model;
  const bool two_d = model != Model::one_d;
  const bool has_normal = model != Model::one_d;
  const bool coupled = model == Model::full3d;
  const bool exact = options_.update == TangentialUpdate::exact_linear;
  const double kt = pair.tangential_stiffness;
  const double kn = pair.normal_stiffness;
  const double mu = pair.friction_coefficient;
  const double n0 = pair.normal_preload;
  const int m = kD ? static_cast<int>(basis->cols()) : 0;
  std::array<double, 2>& d = d_;
  std::array<Anchor, 2>& anchor = anchor_;
  Eigen::Matrix2d& dd0 = dd_start_;  // d(d)/d(d_start)
  if (track) {
    dd0.setIdentity();
    slipped_ = false;
    if constexpr (kD) {
      run_d_[0].clear();
      run_d_[1].clear();
      dense_q_.clear();
    }
  }

  std::array<bool, 2> prev_stick{false, false};
  // Bookkeeping of the derivative of the current period (see LinearizedPeriod).
  auto rec_stick = [&](int i, int l) {
    if constexpr (kD) {
      if (!prev_stick[i]) {
        lin->runs[i].push_back({l, l, -1, 0.0, 0.0});
        lin->run_x[i].row(static_cast<Eigen::Index>(lin->runs[i].size() - 1)) = (i == 0) ? xd_ : yd_;
        if (track) run_d_[i].push_back(dd0);
      } else {
        lin->runs[i].back().last = l;
      }
    }
    prev_stick[i] = true;
  };
  auto rec_none = [&](int i) { prev_stick[i] = false; };
  auto rec_anchor_stick = [&](int i, int l) {
    if constexpr (kD) {
      const Anchor& an = anchor[i];
      auto& runs = lin->runs[i];
      if (!prev_stick[i] || runs.back().anchor != an.s || runs.back().alpha != an.alpha ||
          runs.back().beta != an.beta)
        runs.push_back({l, l, an.s, an.alpha, an.beta});
      else
        runs.back().last = l;
    }
    prev_stick[i] = true;
  };
  auto rec_slip = [&](int i, int l, double weight) {
    if constexpr (kD) lin->slip_weight[i][l] = weight;
    prev_stick[i] = false;
  };

  if constexpr (kD) {
    for (int i = 0; i < 2; ++i) {
      lin->runs[i].clear();
      lin->dense_index[i].clear();
      lin->slip_weight[i].assign(coupled || i >= (two_d ? 2 : 1) ? 0 : n, 0.0);
    }
  }
  for (int l = 0; l < n; ++l) {
    const int lp = (l == 0) ? n - 1 : l - 1;
    const double wx = w(l, 0);
    const double wy = two_d ? w(l, 1) : 0.0;
    double nl = has_normal ? n0 + kn * w(l, 2) : n0;
    const bool pressed = nl > 0.0;
    if (!pressed) nl = 0.0;
    double nprev = has_normal ? n0 + kn * w(lp, 2) : n0;  // N(l-1), for exact_linear
    const bool pressed_prev = nprev > 0.0;
    if (!pressed_prev) nprev = 0.0;
    const double lim = mu * nl;
    double tx = 0.0, ty = 0.0;
    auto e_row = [&](int row) { return basis->row(row); };
    if constexpr (kD) lin->pressed[l] = (pressed && has_normal) ? 1 : 0;

    if (!pressed || !(lim > 0.0)) {
      // Separation (or no friction): no tangential force, the damper follows.
      d = {wx, wy};
      rec_none(0);
      rec_none(1);
      anchor[0] = {l, 1.0, 0.0};
      anchor[1] = {l, 1.0, 0.0};
      if (track) {
        dd0.setZero();
        slipped_ = true;
      }
      if constexpr (kD) {
        xd_.setZero();
        xd_.segment(0, m) = e_row(l);
        if (two_d) {
          yd_.setZero();
          yd_.segment(m, m) = e_row(l);
        }
      }
    } else if (coupled && !exact) {
      // full3d, radial return.
      const double tsx = kt * (wx - d[0]);
      const double tsy = kt * (wy - d[1]);
      const double nt = std::sqrt(tsx * tsx + tsy * tsy);
      if (nt <= lim) {
        tx = tsx;
        ty = tsy;
        rec_stick(0, l);  // dT = kt (dw_t - dd), dd unchanged
        rec_stick(1, l);
      } else {
        const double ex = tsx / nt, ey = tsy / nt;
        tx = lim * ex;
        ty = lim * ey;
        d = {wx - tx / kt, wy - ty / kt};
        const double rho = lim / nt;
        if (track) {
          // d(d_start) only: dT* = -kt D, dT = rho (I - e e^T) dT*, D <- -dT/kt.
          Eigen::Matrix2d proj;
          proj << 1.0 - ex * ex, -ex * ey, -ex * ey, 1.0 - ey * ey;
          const Eigen::Matrix2d md = rho * proj * dd0;
          if constexpr (kD) dense_q_.push_back(-kt * md);
          dd0 = md;
          slipped_ = true;
        }
        if constexpr (kD) {
          // dT = mu dN dir + (mu N/|T*|)(I - dir dir^T) dT*,  dT* = kt (dw_t - dd),
          // dd = dw_t - dT/kt; one fused pass over the P columns, written straight into
          // the dense rows of this sample.
          const Eigen::Index k = static_cast<Eigen::Index>(lin->dense_index[0].size());
          double* rx = lin->dense[0].row(k).data();
          double* ry = lin->dense[1].row(k).data();
          double* xd = xd_.data();
          double* yd = yd_.data();
          const double* el = basis->data() + l;  // column-major: E(l, c) = el[c * n]
          const double mkx = mu * kn * ex, mky = mu * kn * ey, ikt = 1.0 / kt;
          for (int blk = 0; blk < 3; ++blk) {
            const double bx = blk == 0 ? 1.0 : 0.0, by = blk == 1 ? 1.0 : 0.0;
            const double zx = blk == 2 ? mkx : 0.0, zy = blk == 2 ? mky : 0.0;
            for (int k = 0, c = blk * m; k < m; ++k, ++c) {
              const double e = el[static_cast<Eigen::Index>(k) * n];
              const double gx = kt * (bx * e - xd[c]);
              const double gy = kt * (by * e - yd[c]);
              const double pr = ex * gx + ey * gy;
              const double tdx = rho * (gx - ex * pr) + zx * e;
              const double tdy = rho * (gy - ey * pr) + zy * e;
              rx[c] = tdx;
              ry[c] = tdy;
              xd[c] = bx * e - tdx * ikt;
              yd[c] = by * e - tdy * ikt;
            }
          }
          lin->dense_index[0].push_back(l);
          lin->dense_index[1].push_back(l);
        }
        prev_stick = {false, false};
      }
    } else if (coupled) {
      // full3d, exact_linear: elastic displacement e = w_t - d integrated over the step,
      // slip radius linear within the step, from mu N(l-1)/kt to mu N(l)/kt.
      const Eigen::Vector2d e0(w(lp, 0) - d[0], w(lp, 1) - d[1]);
      const Eigen::Vector2d dw(wx - w(lp, 0), wy - w(lp, 1));
      const double a_end = lim / kt;
      const double a = mu * nprev / kt;
      Eigen::Matrix<double, 2, 6> jl;
      bool stuck = false;
      Eigen::Vector2d e1 = exact_linear_step(e0, dw, a, a_end, kD ? &jl : nullptr, &stuck);
      // Forces-only tracking: the step's Jacobian only where it does not simply stick.
      if (!kD && track && !stuck) e1 = exact_linear_step(e0, dw, a, a_end, &jl, &stuck);
      tx = kt * e1.x();
      ty = kt * e1.y();
      d = {wx - e1.x(), wy - e1.y()};
      if (stuck) {  // e1 = e0 + dw: dT = kt (dw_t(l) - dd), dd unchanged
        rec_stick(0, l);
        rec_stick(1, l);
      } else {
        if (track) {
          // d(d_start) only: de1 = J_e0 (-D), dT = kt de1, D <- -de1.
          const Eigen::Matrix2d md = jl.leftCols<2>() * dd0;
          if constexpr (kD) dense_q_.push_back(-kt * md);
          dd0 = md;
          slipped_ = true;
        }
        if constexpr (kD) {
          // de1 = J_e0 (dw_t(lp) - dd) + J_dw (dw_t(l) - dw_t(lp))
          //       + J_a0 mu dN(lp)/kt + J_a1 mu dN(l)/kt;  dT = kt de1, dd = dw_t(l) - de1.
          const double ca = mu * kn / kt;
          const double cp = pressed_prev ? ca : 0.0;
          const Eigen::Index k = static_cast<Eigen::Index>(lin->dense_index[0].size());
          double* rx = lin->dense[0].row(k).data();
          double* ry = lin->dense[1].row(k).data();
          double* xd = xd_.data();
          double* yd = yd_.data();
          const double* el = basis->data() + l;
          const double* ep = basis->data() + lp;
          for (int blk = 0; blk < 3; ++blk) {
            // de1_i = -J_i0 dd_x - J_i1 dd_y + u_i E(lp) + v_i E(l) within block blk
            double u[2], v[2];
            for (int i = 0; i < 2; ++i) {
              u[i] = blk == 0 ? jl(i, 0) - jl(i, 2) : blk == 1 ? jl(i, 1) - jl(i, 3) : jl(i, 4) * cp;
              v[i] = blk == 0 ? jl(i, 2) : blk == 1 ? jl(i, 3) : jl(i, 5) * ca;
            }
            const double bx = blk == 0 ? 1.0 : 0.0, by = blk == 1 ? 1.0 : 0.0;
            for (int k = 0, c = blk * m; k < m; ++k, ++c) {
              const Eigen::Index off = static_cast<Eigen::Index>(k) * n;
              const double e = el[off], eprev = ep[off];
              const double g0 = -jl(0, 0) * xd[c] - jl(0, 1) * yd[c] + u[0] * eprev + v[0] * e;
              const double g1 = -jl(1, 0) * xd[c] - jl(1, 1) * yd[c] + u[1] * eprev + v[1] * e;
              rx[c] = kt * g0;
              ry[c] = kt * g1;
              xd[c] = bx * e - g0;
              yd[c] = by * e - g1;
            }
          }
          lin->dense_index[0].push_back(l);
          lin->dense_index[1].push_back(l);
        }
        prev_stick = {false, false};
      }
    } else {
      // quasi3d (x and y) or 1d (x): independent 1D laws with limit mu N(l). Their slip is
      // memoryless, so the damper derivative is always X_i = alpha E_i(s) + beta E_z(s) for
      // the last slip or separation sample s (an "anchor"; 0 before any): no P-wide rows.
      const int ndir = two_d ? 2 : 1;
      const double ca = has_normal ? mu * kn / kt : 0.0;
      for (int i = 0; i < ndir; ++i) {
        const double wi = (i == 0) ? wx : wy;
        const double wip = w(lp, i);
        double t = 0.0;
        if (!exact) {
          const double ts = kt * (wi - d[i]);
          if (std::abs(ts) <= lim) {
            t = ts;
            rec_anchor_stick(i, l);
          } else {
            const double sg = ts > 0.0 ? 1.0 : -1.0;
            t = lim * sg;
            d[i] = wi - t / kt;
            // dT_i = mu kn sg E_z(l); X_i = E_i(l) - dT_i/kt
            rec_slip(i, l, kt * ca * sg);
            anchor[i] = {l, 1.0, -ca * sg};
          }
        } else {
          // 1D: exact for w linear and the limit linear within the step: clamp to the start
          // limit (a no-op up to round-off), add the increment, clamp to the end limit.
          const double a_end = lim / kt;
          const double a = mu * nprev / kt;
          double e0 = wip - d[i];
          double c_a = 0.0;  // d e0' / d a0 when the start is clamped
          bool start_clamped = false;
          if (std::abs(e0) > a) {
            const double sg = e0 > 0.0 ? 1.0 : -1.0;
            e0 = a * sg;
            c_a = pressed_prev ? sg : 0.0;
            start_clamped = true;
          }
          const double v = e0 + (wi - wip);
          double e1 = v;
          if (std::abs(v) > a_end) {  // slipping at the step end: de1 = sg mu kn E_z(l)/kt
            const double sg = v > 0.0 ? 1.0 : -1.0;
            e1 = a_end * sg;
            rec_slip(i, l, kt * ca * sg);
            anchor[i] = {l, 1.0, -ca * sg};
          } else {
            if (start_clamped) {
              // e1 = a0 sg + w(l) - w(lp): the damper was reset at lp (X_i = E_i(lp) -
              // c_a mu kn E_z(lp)/kt), then the step sticks.
              anchor[i] = {lp, 1.0, -c_a * ca};
            }
            rec_anchor_stick(i, l);
          }
          t = kt * e1;
          d[i] = wi - e1;
        }
        (i == 0 ? tx : ty) = t;
      }
    }

    f(l, 0) = tx;
    f(l, 1) = ty;
    f(l, 2) = has_normal ? nl : 0.0;
  }
}

template PeriodicStatus PeriodicLaw::run<true>(const PairParameters&, const Eigen::MatrixX3d&,
                                               Eigen::MatrixX3d&, const Eigen::MatrixXd*,
                                               LinearizedPeriod*);
template PeriodicStatus PeriodicLaw::run<false>(const PairParameters&, const Eigen::MatrixX3d&,
                                                Eigen::MatrixX3d&, const Eigen::MatrixXd*,
                                                LinearizedPeriod*);

}  // namespace shroudsim::contact
