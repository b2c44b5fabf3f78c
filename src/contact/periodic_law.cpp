#include "contact/periodic_law.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "contact/friction_step.hpp"
#include "core/error.hpp"

namespace shroudsim::contact {

PeriodicLaw::PeriodicLaw(LawOptions options) : options_(options) {
  std::vector<std::string> errors;
  if (!options_.validate(&errors)) throw std::invalid_argument("contact::LawOptions: " + errors[0]);
  if (options_.model == Model::one_d_exact)
    throw std::invalid_argument(
        "contact::PeriodicLaw: model 1d_exact is time-continuous (use jenkins_single_harmonic)");
}

PeriodicStatus PeriodicLaw::evaluate(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                                     const Eigen::MatrixXd* basis, LinearizedPeriod* lin) {
  SHROUDSIM_CHECK((basis == nullptr) == (lin == nullptr), "basis and lin go together");
  SHROUDSIM_CHECK(w.rows() >= 1, "at least one sample");
  if (basis != nullptr) {
    SHROUDSIM_CHECK(basis->rows() == w.rows(), "basis rows = time samples");
    return run<true>(pair, w, f, basis, lin);
  }
  return run<false>(pair, w, f, nullptr, nullptr);
}

PeriodicStatus PeriodicLaw::sample_steps(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                                         std::vector<SampleStep>& steps) {
  const PeriodicStatus status = evaluate(pair, w, f);
  // One more period from the converged damper state (the state at the end of the returned
  // period, which repeats within the period tolerance), each sample's recursion recorded.
  struct Reset {
    std::vector<SampleStep>*& p;
    ~Reset() { p = nullptr; }
  } reset{steps_};
  steps.assign(static_cast<std::size_t>(w.rows()), SampleStep{});
  steps_ = &steps;
  period<false>(pair, w, f, nullptr, nullptr, false);
  return status;
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
// Halvings of a Newton step that does not reduce max|g| before the plain repetition is taken
// (see run()). Landing off a bent slow direction costs ~ the step squared, so each halving
// cuts that by 4; one halving sufficed in the wheel state of issue 13 (measured), and 4 (down to
// 1/16 of the step) bound the cost of a rejected step at 5 periods.
constexpr int kNewtonHalvings = 4;
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
PeriodicStatus PeriodicLaw::run(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                                const Eigen::MatrixXd* basis, LinearizedPeriod* lin) {
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
    lin->prepare(n, p, two_d ? 2 : 1, pair.tangential_stiffness, has_normal ? pair.normal_stiffness : 0.0);
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
  // ~2, the last ones quadratically); if it does not, it is halved up to kNewtonHalvings
  // times, and only then is the plain repetition d <- Phi(d) taken. The halving matters where
  // Phi contracts strongly across a slow direction that bends (two short slips per period
  // that nearly cancel, issue 13): the full step follows the slow direction's tangent and
  // lands off the bent curve, where the strong contraction makes |g| larger than at the
  // start, although the step is mostly right; a shorter one lands closer to the curve.
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
        Eigen::Vector2d delta = ai * Eigen::Vector2d(g[0], g[1]);
        bool accepted = false;
        // The full step first, then shortened ones (see kNewtonHalvings).
        for (int h = 0; h <= kNewtonHalvings && status.periods < options_.max_periods; ++h, delta *= 0.5) {
          const std::array<double, 2> trial{dk[0] + delta.x(), dk[1] + delta.y()};
          if (!std::isfinite(trial[0]) || !std::isfinite(trial[1]) || (delta.x() == 0.0 && delta.y() == 0.0)) break;
          const std::array<double, 2> gt = pass(trial);
          const double gtn = std::max(std::abs(gt[0]), std::abs(gt[1]));
          if (gtn <= tol || gtn < gn) {
            dk = trial;
            g = gt;
            gn = gtn;
            jk = dd_start_;
            slipped = slipped_;
            accepted = true;
            break;
          }
        }
        if (accepted) continue;
        if (status.periods >= options_.max_periods) break;
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
    if (!fixed_point_dc_.isZero(0.0)) add_fixed_point_term(*lin, fixed_point_dc_, run_d_, dense_q_);
  }
  return status;
}

struct PeriodicLaw::Sample {
  int l = 0, lp = 0;            // the sample and the one before it (l - 1, cyclically)
  double wx = 0.0, wy = 0.0;    // w_t(l) [m] (wy = 0 for the 1d model)
  double wpx = 0.0, wpy = 0.0;  // w_t(lp) [m]
  double lim = 0.0;             // mu N(l) [N]
  double nprev = 0.0;           // N(lp) [N], for exact_linear
  bool pressed_prev = false;    // N0 + kn z(lp) > 0
  // exact_linear, the contact closes within the step (open at lp, pressed at l): the fraction
  // r of the step after the closing instant, where the normal load, linear within the step,
  // crosses zero (docs/physics.md section 4, "Separation and re-contact"), and its
  // derivatives with respect to z(l) and z(lp) [1/m].
  bool closing = false;
  double r = 1.0, dr_dz = 0.0, dr_dz_prev = 0.0;
};

// The updates of one sample, forced inline into period()'s sample loop: a call per sample is
// a large part of the cost of a forces-only evaluation.

template <bool kD>
[[gnu::always_inline]] inline void PeriodicLaw::separate(const Sample& s, const Eigen::MatrixXd* basis,
                                                         PeriodRecorder* rec, bool track) {
  d_ = {s.wx, s.wy};
  if constexpr (kD) {
    rec->release(0);
    rec->release(1);
  }
  anchor_[0] = {s.l, 1.0, 0.0};
  anchor_[1] = {s.l, 1.0, 0.0};
  if (steps_ != nullptr) {  // d(l) = w_t(l)
    SampleStep& st = (*steps_)[static_cast<std::size_t>(s.l)];
    st.b(0, 0) = 1.0;
    if (options_.model != Model::one_d) st.b(1, 1) = 1.0;
  }
  if (track) {
    dd_start_.setZero();
    slipped_ = true;
  }
  if constexpr (kD) {
    const int m = static_cast<int>(basis->cols());
    xd_.setZero();
    xd_.segment(0, m) = basis->row(s.l);
    if (options_.model != Model::one_d) {
      yd_.setZero();
      yd_.segment(m, m) = basis->row(s.l);
    }
  }
}

template <bool kD>
[[gnu::always_inline]] inline void PeriodicLaw::record_coupled_stick(int l, PeriodRecorder* rec, bool track) {
  // dT = kt (dw_t - dd), dd unchanged: the runs' damper derivative is the current one.
  if (steps_ != nullptr) (*steps_)[static_cast<std::size_t>(l)].a.setIdentity();
  if constexpr (kD) {
    if (rec->stick(0, l, xd_) && track) run_d_[0].push_back(dd_start_);
    if (rec->stick(1, l, yd_) && track) run_d_[1].push_back(dd_start_);
  }
}

template <bool kD>
[[gnu::always_inline]] inline void PeriodicLaw::track_coupled_slip(const Eigen::Matrix2d& md, double kt) {
  if constexpr (kD) dense_q_.push_back(-kt * md);
  dd_start_ = md;
  slipped_ = true;
}

template <bool kD>
[[gnu::always_inline]] inline std::array<double, 2> PeriodicLaw::coupled_radial_return(
    const PairParameters& pair, const Sample& s, const Eigen::MatrixXd* basis, PeriodRecorder* rec, bool track) {
  const double kt = pair.tangential_stiffness;
  const RadialReturn r = radial_return(s.wx, s.wy, d_, kt, s.lim);
  if (r.stick) {
    record_coupled_stick<kD>(s.l, rec, track);
    return {r.tx, r.ty};
  }
  Eigen::Matrix2d proj;  // I - e e^T
  proj << 1.0 - r.ex * r.ex, -r.ex * r.ey, -r.ex * r.ey, 1.0 - r.ey * r.ey;
  if (track) {
    // d(d_start) only: dT* = -kt D, dT = rho (I - e e^T) dT*, D <- -dT/kt.
    const Eigen::Matrix2d md = r.rho * proj * dd_start_;
    track_coupled_slip<kD>(md, kt);
  }
  if (steps_ != nullptr) {
    // dT = mu kn dz(l) e + rho (I - e e^T) kt (dw_t(l) - dd(l-1)), dd(l) = dw_t(l) - dT / kt.
    SampleStep& st = (*steps_)[static_cast<std::size_t>(s.l)];
    st.a = r.rho * proj;
    st.b.leftCols<2>() = Eigen::Matrix2d::Identity() - r.rho * proj;
    st.b.col(2) = -(pair.friction_coefficient * pair.normal_stiffness / kt) * Eigen::Vector2d(r.ex, r.ey);
  }
  if constexpr (kD)
    rec->radial_return_slip(*basis, s.l, kt, pair.normal_stiffness, pair.friction_coefficient, r.ex, r.ey, r.rho, xd_,
                            yd_);
  return {r.tx, r.ty};
}

template <bool kD>
[[gnu::always_inline]] inline std::array<double, 2> PeriodicLaw::coupled_exact_linear(const PairParameters& pair,
                                                                                      const Sample& s,
                                                                                      const Eigen::MatrixXd* basis,
                                                                                      PeriodRecorder* rec, bool track) {
  // Elastic displacement e = w_t - d integrated over the step, slip radius linear within the
  // step, from mu N(l-1)/kt to mu N(l)/kt.
  const double kt = pair.tangential_stiffness;
  const double mu = pair.friction_coefficient;
  const double a_end = s.lim / kt;
  const double ca = mu * pair.normal_stiffness / kt;  // d(slip radius)/dz
  Eigen::Matrix<double, 2, 6> jl;
  bool stuck = false;
  if (s.closing) {
    // The contact closes within the step: the slider is where the motion was at the closing
    // instant (e = 0 there, whatever d was), and the step integrates the remaining fraction r
    // with the slip radius growing from 0. The damper moves in this step even if it sticks,
    // so the sample is an explicit row: de1 = r J_dw (E_t(l) - E_t(lp))
    //   + J_dw dw (dr/dz(l) E_z(l) + dr/dz(lp) E_z(lp)) + J_a1 da1, J_e0 = J_a0 = 0.
    const Eigen::Vector2d dw(s.wx - s.wpx, s.wy - s.wpy);
    const Eigen::Vector2d e1 = exact_linear_step(Eigen::Vector2d::Zero(), s.r * dw, 0.0, a_end,
                                                 (kD || track || steps_ != nullptr) ? &jl : nullptr, &stuck);
    d_ = {s.wx - e1.x(), s.wy - e1.y()};
    if (kD || track || steps_ != nullptr) {
      const Eigen::Vector2d jdw = jl.middleCols<2>(2) * dw;  // de1/dr
      jl.leftCols<2>().setZero();
      jl.col(4).setZero();
      jl.middleCols<2>(2) *= s.r;
      if (steps_ != nullptr) {  // dd(l) = dw_t(l) - de1, no dependence on dd(l-1)
        SampleStep& st = (*steps_)[static_cast<std::size_t>(s.l)];
        st.b.leftCols<2>() = Eigen::Matrix2d::Identity() - jl.middleCols<2>(2);
        st.b.col(2) = -(s.dr_dz * jdw + ca * jl.col(5));
        st.c.leftCols<2>() = jl.middleCols<2>(2);
        st.c.col(2) = -s.dr_dz_prev * jdw;
      }
      if (track) track_coupled_slip<kD>(Eigen::Matrix2d::Zero(), kt);  // e1 does not depend on d_start
      if constexpr (kD)
        rec->exact_linear_slip(*basis, s.l, s.lp, kt, pair.normal_stiffness, mu, false, jl, xd_, yd_,
                               {s.dr_dz_prev * jdw.x(), s.dr_dz_prev * jdw.y()},
                               {s.dr_dz * jdw.x(), s.dr_dz * jdw.y()});
    }
    return {kt * e1.x(), kt * e1.y()};
  }
  const Eigen::Vector2d e0(s.wpx - d_[0], s.wpy - d_[1]);
  const Eigen::Vector2d dw(s.wx - s.wpx, s.wy - s.wpy);
  const double a = mu * s.nprev / kt;
  Eigen::Vector2d e1 = exact_linear_step(e0, dw, a, a_end, kD ? &jl : nullptr, &stuck);
  // Forces-only tracking: the step's Jacobian only where it does not simply stick.
  if (!kD && (track || steps_ != nullptr) && !stuck) e1 = exact_linear_step(e0, dw, a, a_end, &jl, &stuck);
  d_ = {s.wx - e1.x(), s.wy - e1.y()};
  if (stuck) {  // e1 = e0 + dw
    record_coupled_stick<kD>(s.l, rec, track);
  } else {
    if (track) {
      // d(d_start) only: de1 = J_e0 (-D), dT = kt de1, D <- -de1.
      const Eigen::Matrix2d md = jl.leftCols<2>() * dd_start_;
      track_coupled_slip<kD>(md, kt);
    }
    if constexpr (kD)
      rec->exact_linear_slip(*basis, s.l, s.lp, kt, pair.normal_stiffness, mu, s.pressed_prev, jl, xd_, yd_);
    if (steps_ != nullptr) {
      // de1 = J_e0 (dw_t(l-1) - dd(l-1)) + J_dw (dw_t(l) - dw_t(l-1)) + J_a0 da0 + J_a1 da1,
      // dd(l) = dw_t(l) - de1.
      SampleStep& st = (*steps_)[static_cast<std::size_t>(s.l)];
      st.a = jl.leftCols<2>();
      st.b.leftCols<2>() = Eigen::Matrix2d::Identity() - jl.middleCols<2>(2);
      st.b.col(2) = -ca * jl.col(5);
      st.c.leftCols<2>() = jl.middleCols<2>(2) - jl.leftCols<2>();
      if (s.pressed_prev) st.c.col(2) = -ca * jl.col(4);
    }
  }
  return {kt * e1.x(), kt * e1.y()};
}

template <bool kD>
[[gnu::always_inline]] inline std::array<double, 2> PeriodicLaw::uncoupled(const PairParameters& pair, const Sample& s,
                                                                           const Eigen::MatrixXd* basis,
                                                                           PeriodRecorder* rec) {
  // quasi3d (x and y) or 1d (x): independent 1D laws with limit mu N(l). Their slip is
  // memoryless, so the damper derivative is always X_i = alpha E_i(s) + beta E_z(s) for
  // the last slip or separation sample s (an "anchor"; 0 before any): no P-wide rows.
  const bool two_d = options_.model != Model::one_d;
  const bool has_normal = options_.model != Model::one_d;
  const bool exact = options_.update == TangentialUpdate::exact_linear;
  const double kt = pair.tangential_stiffness;
  const double kn = pair.normal_stiffness;
  const double mu = pair.friction_coefficient;
  const int ndir = two_d ? 2 : 1;
  const double ca = has_normal ? mu * kn / kt : 0.0;
  std::array<double, 2> t{0.0, 0.0};
  for (int i = 0; i < ndir; ++i) {
    const double wi = (i == 0) ? s.wx : s.wy;
    const double wpi = (i == 0) ? s.wpx : s.wpy;
    AxisStep step;
    if (!exact) {
      step = axis_radial_return(wi, d_[i], kt, s.lim);
    } else if (s.closing) {
      step = axis_closing(wi, wpi, s.r, d_[i], kt, s.lim / kt);
      if (step.slip == 0.0) {
        // Stuck from the closing instant: d = (1 - r) w(l) + r w(lp), so the damper
        // derivative X_i = (1 - r) E_i(l) + r E_i(lp) - (w(l) - w(lp)) (dr/dz(l) E_z(l) +
        // dr/dz(lp) E_z(lp)) spans four basis rows: an explicit run row (xd_ / yd_), held
        // until the next slip or separation.
        if constexpr (kD) {
          Eigen::RowVectorXd& x = i == 0 ? xd_ : yd_;
          const int m = static_cast<int>(basis->cols());
          const double dwi = wi - wpi;
          x.setZero();
          x.segment(i * m, m) = (1.0 - s.r) * basis->row(s.l) + s.r * basis->row(s.lp);
          x.segment(2 * m, m) = -dwi * (s.dr_dz * basis->row(s.l) + s.dr_dz_prev * basis->row(s.lp));
        }
        anchor_[i] = {-1, 0.0, 0.0, true};
      }
    } else {
      const double a_end = s.lim / kt;
      const double a = mu * s.nprev / kt;
      step = axis_exact_linear(wi, wpi, d_[i], kt, a, a_end);
    }
    if (step.slip != 0.0) {
      // Slipping at the sample: dT_i = sg mu kn E_z(l); X_i = E_i(l) - dT_i/kt.
      if constexpr (kD) rec->slip(i, s.l, kt * ca * step.slip);
      anchor_[i] = {s.l, 1.0, -ca * step.slip};
    } else {
      if (step.start != 0.0) {
        // exact_linear, start clamped: e1 = a0 sg + w(l) - w(lp), the damper was reset at lp
        // (X_i = E_i(lp) - c_a mu kn E_z(lp)/kt), then the step sticks.
        const double c_a = s.pressed_prev ? step.start : 0.0;
        anchor_[i] = {s.lp, 1.0, -c_a * ca};
      }
      if constexpr (kD) {
        if (anchor_[i].explicit_x) rec->stick(i, s.l, i == 0 ? xd_ : yd_);
        else rec->stick_anchored(i, s.l, anchor_[i].s, anchor_[i].alpha, anchor_[i].beta);
      }
    }
    if (steps_ != nullptr) {
      // The row of axis i: d(l) = w(l) - e(l) with e clamped (slip), taken from the closing
      // instant, reset at l-1 (a clamped start), or held (stick).
      SampleStep& st = (*steps_)[static_cast<std::size_t>(s.l)];
      if (step.slip != 0.0) {
        st.b(i, i) = 1.0;
        st.b(i, 2) = -step.slip * ca;
      } else if (exact && s.closing) {
        st.b(i, i) = 1.0 - s.r;
        st.c(i, i) = s.r;
        st.b(i, 2) = -(wi - wpi) * s.dr_dz;
        st.c(i, 2) = -(wi - wpi) * s.dr_dz_prev;
      } else if (step.start != 0.0) {
        st.c(i, i) = 1.0;
        st.c(i, 2) = s.pressed_prev ? -step.start * ca : 0.0;
      } else {
        st.a(i, i) = 1.0;
      }
    }
    t[static_cast<std::size_t>(i)] = step.t;
  }
  return t;
}

template <bool kD>
void PeriodicLaw::period(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                         const Eigen::MatrixXd* basis, LinearizedPeriod* lin, bool track) {
  const int n = static_cast<int>(w.rows());
  const Model model = options_.model;
  const bool two_d = model != Model::one_d;
  const bool has_normal = model != Model::one_d;
  const bool coupled = model == Model::full3d;
  const bool exact = options_.update == TangentialUpdate::exact_linear;
  const double kn = pair.normal_stiffness;
  const double mu = pair.friction_coefficient;
  const double n0 = pair.normal_preload;
  if (track) {
    dd_start_.setIdentity();  // d(d)/d(d_start)
    slipped_ = false;
    if constexpr (kD) {
      run_d_[0].clear();
      run_d_[1].clear();
      dense_q_.clear();
    }
  }
  // Bookkeeping of the derivative of the current period (see LinearizedPeriod).
  std::optional<PeriodRecorder> recorder;
  if constexpr (kD) recorder.emplace(*lin, n, coupled ? 0 : (two_d ? 2 : 1));
  PeriodRecorder* rec = recorder ? &*recorder : nullptr;

  for (int l = 0; l < n; ++l) {
    Sample s;
    s.l = l;
    s.lp = (l == 0) ? n - 1 : l - 1;
    s.wx = w(l, 0);
    s.wy = two_d ? w(l, 1) : 0.0;
    s.wpx = w(s.lp, 0);
    s.wpy = two_d ? w(s.lp, 1) : 0.0;
    const double nl_raw = has_normal ? n0 + kn * w(l, 2) : n0;
    const double np_raw = has_normal ? n0 + kn * w(s.lp, 2) : n0;
    const bool pressed = nl_raw > 0.0;
    const double nl = pressed ? nl_raw : 0.0;
    s.pressed_prev = np_raw > 0.0;
    s.nprev = s.pressed_prev ? np_raw : 0.0;
    s.lim = mu * nl;
    if (exact && has_normal && pressed && !s.pressed_prev) {
      // r = N(l) / (N(l) - N(lp)) in (0, 1], N(lp) <= 0 < N(l).
      const double span = nl_raw - np_raw;
      s.closing = true;
      s.r = nl_raw / span;
      s.dr_dz = -kn * np_raw / (span * span);
      s.dr_dz_prev = kn * nl_raw / (span * span);
    }
    if constexpr (kD) rec->set_pressed(l, pressed && has_normal);
    if (steps_ != nullptr) (*steps_)[static_cast<std::size_t>(l)].pressed = pressed && has_normal;

    std::array<double, 2> t{0.0, 0.0};
    if (!pressed || !(s.lim > 0.0)) separate<kD>(s, basis, rec, track);
    else if (coupled && !exact) t = coupled_radial_return<kD>(pair, s, basis, rec, track);
    else if (coupled) t = coupled_exact_linear<kD>(pair, s, basis, rec, track);
    else t = uncoupled<kD>(pair, s, basis, rec);
    f(l, 0) = t[0];
    f(l, 1) = t[1];
    f(l, 2) = has_normal ? nl : 0.0;
  }
}

template PeriodicStatus PeriodicLaw::run<true>(const PairParameters&, const Eigen::MatrixX3d&, Eigen::MatrixX3d&,
                                               const Eigen::MatrixXd*, LinearizedPeriod*);
template PeriodicStatus PeriodicLaw::run<false>(const PairParameters&, const Eigen::MatrixX3d&, Eigen::MatrixX3d&,
                                                const Eigen::MatrixXd*, LinearizedPeriod*);

}  // namespace shroudsim::contact
