#include "forced/stability.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "linalg/blas.hpp"
#include "linalg/dense_eigen.hpp"

namespace shroudsim::forced {
namespace {
using Complex = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Half a harmonic: the symmetric copy's eigenvector centroid lies within it. An exponent at
// w / 2 (a negative real multiplier, period doubling) has its two copies' eigenvectors split
// between two neighbouring blocks, centroids near +-0.5: a strict half harmonic dropped both
// copies of such an exponent wherever they fell just outside (stress model 8 at 0.0690 Hz: -0.0955 w
// +- 0.49995 i w at centroids -+0.505, the shooting's dominant multiplier). The margin keeps
// both copies (the same multiplier twice) and stays far from the next copies at +-1.
constexpr double kCentroidHalfWidth = 0.6;
// With the slider as a state, an eigenvector whose structural part is round-off against its
// damper part (|Phi q| / |sigma| below this: 1e-17 measured, against 1e-2 for the stuck
// slider's neutral exponent) is a damper motion the 2H + 1 harmonics do not see: the damper
// recursion alone, whose multipliers are products of the samples' contractions (stable or
// neutral). Not a Floquet exponent of the truncated structure; not kept.
constexpr double kSliderOnly = 1e-8;
// The Hill operator in the real harmonic coordinates is real; its transform from the
// exponential form is taken as real when the imaginary parts are round-off of this size
// relative to the largest entry (they are exact zeros up to the products' rounding).
constexpr double kRealFormTolerance = 1e-10;
// stability_changes: a critical exponent whose imaginary part is within this many w of 0 (or
// of w / 2) is a real crossing (or a period doubling); the companion eigenvalues of a real
// exponent carry an imaginary part of round-off size only.
constexpr double kKindTolerance = 0.05;

/// The eigenvalues (and eigenvectors, in exponential coordinates) of the Hill companion
/// matrix, given in exponential coordinates (blocks k = -H..H at offset[k + H], in both halves
/// [q; mu q]). The same operator in the real coordinates of the harmonic balance (X_0; c_n, s_n
/// with X_n = (c_n - i s_n) / 2, X_-n = (c_n + i s_n) / 2) is real: there LAPACK's dgeev costs
/// about a quarter of zgeev on the complex form. Falls back to the complex form when the
/// transformed matrix is not real to round-off.
linalg::DenseEigen hill_eigen(const Eigen::MatrixXcd& companion, const std::vector<Eigen::Index>& offset, int h,
                              bool with_vectors) {
  const Eigen::Index s = offset.back(), n2 = 2 * s;
  // Index triples per harmonic n >= 1 and local DOF j: (X_n, X_-n) -> (c_n, s_n); n = 0 maps 1:1.
  struct Pair {
    Eigen::Index xp, xm, rc, rs;
  };
  std::vector<Pair> pairs;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> zero;  // (X_0, r_0)
  Eigen::Index r = 0;
  for (Eigen::Index half = 0; half < 2; ++half) {
    const Eigen::Index base = half * s;
    const Eigen::Index m0 = offset[static_cast<std::size_t>(h + 1)] - offset[static_cast<std::size_t>(h)];
    for (Eigen::Index j = 0; j < m0; ++j) zero.emplace_back(base + offset[static_cast<std::size_t>(h)] + j, r++);
    for (int n = 1; n <= h; ++n) {
      const Eigen::Index op = offset[static_cast<std::size_t>(h + n)], om = offset[static_cast<std::size_t>(h - n)];
      const Eigen::Index m = offset[static_cast<std::size_t>(h + n + 1)] - op;
      for (Eigen::Index j = 0; j < m; ++j, r += 2) pairs.push_back({base + op + j, base + om + j, r, r + 1});
    }
  }
  const Complex i1(0.0, 1.0);
  // B = C S (columns), then R = S^-1 B (rows).
  Eigen::MatrixXcd b(n2, n2);
  for (const auto& [x, rr] : zero) b.col(rr) = companion.col(x);
  for (const Pair& p : pairs) {
    b.col(p.rc) = 0.5 * (companion.col(p.xp) + companion.col(p.xm));
    b.col(p.rs) = 0.5 * i1 * (companion.col(p.xm) - companion.col(p.xp));
  }
  Eigen::MatrixXcd real_form(n2, n2);
  for (const auto& [x, rr] : zero) real_form.row(rr) = b.row(x);
  for (const Pair& p : pairs) {
    real_form.row(p.rc) = b.row(p.xp) + b.row(p.xm);
    real_form.row(p.rs) = i1 * (b.row(p.xp) - b.row(p.xm));
  }
  if (real_form.imag().cwiseAbs().maxCoeff() > kRealFormTolerance * real_form.real().cwiseAbs().maxCoeff())
    return linalg::dense_eigen(companion, with_vectors);
  linalg::DenseEigen out = linalg::dense_eigen(Eigen::MatrixXd(real_form.real()), with_vectors);
  if (with_vectors) {
    Eigen::MatrixXcd v(n2, n2);
    for (const auto& [x, rr] : zero) v.row(x) = out.vectors.row(rr);
    for (const Pair& p : pairs) {
      v.row(p.xp) = 0.5 * (out.vectors.row(p.rc) - i1 * out.vectors.row(p.rs));
      v.row(p.xm) = 0.5 * (out.vectors.row(p.rc) + i1 * out.vectors.row(p.rs));
    }
    out.vectors = std::move(v);
  }
  return out;
}

// The shift of the spectral transformation that solves the slider-state pencil A y = mu B y
// (B singular where samples carry no memory: infinite eigenvalues): the eigenvalues of
// (A - kShift B)^-1 B are 1 / (mu - kShift). A growth of a quarter of w per unit time is no
// physical exponent, so A - kShift B is regular.
constexpr double kShift = 0.25;
// Eigenvalues nu of the transformed problem below this are infinite ones (|mu| > 1e9).
constexpr double kInfinite = 1e-9;

/// The unknowns and the pencil of Hill's method with the slider as a state for one family
/// (docs/physics.md section 9, "Friction: the slider as a state"). y = [q; mu q; sigma]:
/// q the modal (or lumped) unknowns of the blocks (s), sigma the damper positions of every
/// pair, tangential direction and sample (periodic parts, e^{lambda t} factored out). The
/// contact relative displacement W = Phi q - R F (exponential harmonics), its samples
/// psi = Gamma W, the forces f = kt (psi_t - sigma), kn psi_z where pressed, F = Pi f.
/// Each sample with memory: (1 + mu theta) sigma(l) = (1 - mu theta) (a sigma(l-1) +
/// c psi(l-1)) + (1 + mu theta) b psi(l), theta = pi / N (the Cayley form of e^{-lambda dt});
/// without memory sigma(l) = b psi(l).
struct SliderPencil {
  Eigen::MatrixXcd a, b;
  std::vector<Eigen::Index> algebraic;  ///< the rows (and unknowns) without memory: B's row is 0
};
SliderPencil slider_state_pencil(const Eigen::MatrixXcd& a0, const Eigen::MatrixXcd& a1, const Eigen::MatrixXd& a2,
                                 const Eigen::MatrixXcd& phi, const std::vector<const Eigen::MatrixXcd*>& r, int h,
                                 int c, int nd, double omega, const ContactMemory& memory,
                                 const Eigen::MatrixXcd& correction) {
  const Complex i1(0.0, 1.0);
  const int np = static_cast<int>(memory.pairs.size());
  const int nt = contact::n_tangential_directions(memory.model);
  const int n = static_cast<int>(memory.steps.front().size());
  const Eigen::Index s = a0.rows(), ne = phi.rows(), ns = static_cast<Eigen::Index>(np) * nt * n;
  const auto wi = [&](int k, int p, int d) { return static_cast<Eigen::Index>(k + h) * c + 3 * p + d; };
  const auto si = [&](int p, int i, int l) { return static_cast<Eigen::Index>(p * nt + i) * n + l; };
  const auto psi_i = [&](int p, int d, int l) { return static_cast<Eigen::Index>(p * nd + d) * n + l; };
  // e^{i j theta_l}, j = -2H..2H.
  Eigen::MatrixXcd ex(4 * h + 1, n);
  for (int j = -2 * h; j <= 2 * h; ++j)
    for (int l = 0; l < n; ++l) ex(j + 2 * h, l) = std::polar(1.0, kTwoPi * j * l / n);
  const auto e = [&](int j, int l) { return ex(j + 2 * h, l); };

  // The memoryless part D0 = Pi diag(g) Gamma (g = kt tangential, kn pressed normal) and the
  // damper's S = Pi kt (F = D0 W - S sigma).
  Eigen::MatrixXcd d0 = Eigen::MatrixXcd::Zero(ne, ne), sm = Eigen::MatrixXcd::Zero(ne, ns);
  for (int p = 0; p < np; ++p) {
    const contact::PairParameters& pair = memory.pairs[static_cast<std::size_t>(p)];
    const auto& steps = memory.steps[static_cast<std::size_t>(p)];
    for (int d = 0; d < nd; ++d) {
      Eigen::VectorXcd g_hat = Eigen::VectorXcd::Zero(4 * h + 1);
      for (int l = 0; l < n; ++l) {
        const double g = d < nt ? pair.tangential_stiffness
                                : (steps[static_cast<std::size_t>(l)].pressed ? pair.normal_stiffness : 0.0);
        if (g == 0.0) continue;
        for (int j = -2 * h; j <= 2 * h; ++j) g_hat(j + 2 * h) += g * std::conj(e(j, l)) / double(n);
      }
      for (int k = -h; k <= h; ++k)
        for (int k2 = -h; k2 <= h; ++k2) d0(wi(k, p, d), wi(k2, p, d)) = g_hat(k - k2 + 2 * h);
    }
    for (int i = 0; i < nt; ++i)
      for (int k = -h; k <= h; ++k)
        for (int l = 0; l < n; ++l) sm(wi(k, p, i), si(p, i, l)) = pair.tangential_stiffness / n * std::conj(e(k, l));
  }
  // The coarse memory's correction to the harmonic balance's dF/dW is memoryless (ContactMemory).
  if (correction.size() > 0) d0 += correction;
  // W = Wq q + Ws sigma: (I + R D0) W = Phi q + R S sigma.
  Eigen::MatrixXcd wq = phi, ws = Eigen::MatrixXcd::Zero(ne, ns);
  bool with_r = false;
  Eigen::MatrixXcd rm = Eigen::MatrixXcd::Zero(ne, ne);
  for (int k = -h; k <= h; ++k) {
    const Eigen::MatrixXcd* rk = r[static_cast<std::size_t>(k + h)];
    if (rk == nullptr) continue;
    with_r = true;
    rm.block(static_cast<Eigen::Index>(k + h) * c, static_cast<Eigen::Index>(k + h) * c, c, c) = *rk;
  }
  if (with_r) {
    const Eigen::PartialPivLU<Eigen::MatrixXcd> z(Eigen::MatrixXcd::Identity(ne, ne) + rm * d0);
    wq = z.solve(phi);
    ws = z.solve(rm * sm);
  }
  const Eigen::MatrixXcd fq = d0 * wq, fs = d0 * ws - sm;
  // The samples psi = Gamma W of every pair and direction.
  Eigen::MatrixXcd psq = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(np) * nd * n, s),
                   pss = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(np) * nd * n, ns);
  for (int p = 0; p < np; ++p)
    for (int d = 0; d < nd; ++d)
      for (int l = 0; l < n; ++l)
        for (int k = -h; k <= h; ++k) {
          psq.row(psi_i(p, d, l)) += e(k, l) * wq.row(wi(k, p, d));
          if (with_r) pss.row(psi_i(p, d, l)) += e(k, l) * ws.row(wi(k, p, d));
        }

  SliderPencil out;
  const Eigen::Index size = 2 * s + ns;
  out.a = Eigen::MatrixXcd::Zero(size, size);
  out.b = Eigen::MatrixXcd::Zero(size, size);
  out.a.block(0, s, s, s).setIdentity();
  out.b.block(0, 0, s, s).setIdentity();
  const double w2 = omega * omega;
  out.a.block(s, 0, s, s) = -(a0 + phi.adjoint() * fq / w2);
  out.a.block(s, s, s, s) = -a1;
  out.a.block(s, 2 * s, s, ns) = -phi.adjoint() * fs / w2;
  out.b.block(s, s, s, s) = a2.cast<Complex>();
  const double theta = std::numbers::pi / n;
  Eigen::RowVectorXcd minus(size), plus(size);
  for (int p = 0; p < np; ++p) {
    const auto& steps = memory.steps[static_cast<std::size_t>(p)];
    for (int i = 0; i < nt; ++i)
      for (int l = 0; l < n; ++l) {
        const int lp = (l + n - 1) % n;
        const contact::SampleStep& st = steps[static_cast<std::size_t>(l)];
        minus.setZero();
        plus.setZero();
        // Adds coef * psi_d(l') to row v.
        const auto add_psi = [&](Eigen::RowVectorXcd& v, double coef, int d, int ll) {
          if (coef == 0.0 || d >= nd) return;
          v.head(s) += coef * psq.row(psi_i(p, d, ll));
          if (with_r) v.tail(ns) += coef * pss.row(psi_i(p, d, ll));
        };
        minus(2 * s + si(p, i, l)) = 1.0;
        plus(2 * s + si(p, i, l)) = 1.0;
        for (int d = 0; d < 3; ++d) {
          add_psi(minus, -st.b(i, d), d, l);
          add_psi(plus, -st.b(i, d), d, l);
        }
        const bool memory_row = !st.a.row(i).isZero(0.0) || !st.c.row(i).isZero(0.0);
        const Eigen::Index row = 2 * s + si(p, i, l);
        if (!memory_row) {
          out.a.row(row) = minus;  // sigma(l) = b psi(l)
          out.algebraic.push_back(row);
          continue;
        }
        for (int j = 0; j < nt; ++j) {
          minus(2 * s + si(p, j, lp)) -= st.a(i, j);
          plus(2 * s + si(p, j, lp)) += st.a(i, j);
        }
        for (int d = 0; d < 3; ++d) {
          add_psi(minus, -st.c(i, d), d, lp);
          add_psi(plus, st.c(i, d), d, lp);
        }
        out.a.row(row) = minus;
        out.b.row(row) = -theta * plus;
      }
  }
  return out;
}

/// The finite eigenvalues mu of the pencil A y = mu B y and their eigenvectors. The unknowns of
/// the algebraic rows (f, B_f. = 0) are eliminated first: A_ff y_f = -A_fk y_k, so the pencil
/// of the others is A_kk - A_kf X - mu (B_kk - B_kf X), X = A_ff^-1 A_fk (samples without
/// memory: separated, or slipping in an uncoupled law; the dense solve's cost falls with the
/// cube of what is left).
linalg::DenseEigen pencil_eigen(const SliderPencil& pencil) {
  const Eigen::Index n = pencil.a.rows(), nf = static_cast<Eigen::Index>(pencil.algebraic.size()), nk = n - nf;
  // order: the kept unknowns, then the algebraic ones.
  std::vector<Eigen::Index> order;
  std::vector<char> algebraic(static_cast<std::size_t>(n), 0);
  for (Eigen::Index r : pencil.algebraic) algebraic[static_cast<std::size_t>(r)] = 1;
  for (Eigen::Index r = 0; r < n; ++r)
    if (algebraic[static_cast<std::size_t>(r)] == 0) order.push_back(r);
  order.insert(order.end(), pencil.algebraic.begin(), pencil.algebraic.end());
  Eigen::MatrixXcd pa(n, n), pb(n, n);
  for (Eigen::Index c = 0; c < n; ++c)
    for (Eigen::Index r = 0; r < n; ++r) {
      pa(r, c) = pencil.a(order[static_cast<std::size_t>(r)], order[static_cast<std::size_t>(c)]);
      pb(r, c) = pencil.b(order[static_cast<std::size_t>(r)], order[static_cast<std::size_t>(c)]);
    }
  Eigen::MatrixXcd a = pa.topLeftCorner(nk, nk), b = pb.topLeftCorner(nk, nk), x;
  if (nf > 0) {
    x = pa.bottomRightCorner(nf, nf).partialPivLu().solve(pa.bottomLeftCorner(nf, nk));
    a -= pa.topRightCorner(nk, nf) * x;
    b -= pb.topRightCorner(nk, nf) * x;
  }
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(a - kShift * b);
  const Eigen::MatrixXcd t = lu.solve(b);
  if (!t.allFinite()) throw NumericalError("the slider-state Hill matrix is not finite");
  const linalg::DenseEigen nu = linalg::dense_eigen(t, true);
  linalg::DenseEigen out;
  std::vector<Eigen::Index> finite;
  for (Eigen::Index j = 0; j < nu.values.size(); ++j)
    if (std::abs(nu.values[j]) > kInfinite) finite.push_back(j);
  out.values.resize(static_cast<Eigen::Index>(finite.size()));
  out.vectors.resize(n, static_cast<Eigen::Index>(finite.size()));
  for (std::size_t j = 0; j < finite.size(); ++j) {
    out.values[static_cast<Eigen::Index>(j)] = kShift + 1.0 / nu.values[finite[j]];
    Eigen::VectorXcd y(n);
    y.head(nk) = nu.vectors.col(finite[j]);
    if (nf > 0) y.tail(nf) = -x * y.head(nk);
    for (Eigen::Index r = 0; r < n; ++r)
      out.vectors(order[static_cast<std::size_t>(r)], static_cast<Eigen::Index>(j)) = y(r);
  }
  return out;
}
}  // namespace

int memory_samples(int requested, int time_samples, int harmonics, int dampers) {
  const int least = 2 * harmonics + 1;
  if (requested > 0) return std::min(std::max(requested, least), time_samples);
  if (dampers <= 0 || static_cast<long long>(time_samples) * dampers <= kMaxMemoryUnknowns) return time_samples;
  return std::min(time_samples, std::max(least, kMaxMemoryUnknowns / dampers));
}

bool ContactMemory::carries_memory() const {
  for (const auto& pair : steps)
    for (const contact::SampleStep& st : pair)
      if (!st.a.isZero(0.0) || !st.c.isZero(0.0)) return true;
  return false;
}

ContactMemory contact_memory(ReducedEquations& equations, const Eigen::VectorXd& w, int samples,
                             const std::vector<Eigen::MatrixXd>* jacobian) {
  ContactMemory out;
  hbm::ContactEvaluator& contacts = equations.contacts();
  out.model = contacts.options().law.model;
  out.pairs = contacts.pairs();
  if (samples <= 0 || samples >= contacts.options().n_time_samples) {
    out.steps = contacts.sample_steps(w);
    return out;
  }
  // The same law replayed at `samples` points on the same harmonics (a serial evaluator of its
  // own: this one may be shared).
  hbm::ContactEvaluatorOptions options = contacts.options();
  options.n_time_samples = samples;
  options.threads = 1;
  options.measure_plans = false;
  options.jacobian = hbm::JacobianMethod::analytic;
  hbm::ContactEvaluator coarse(options, out.pairs);
  out.steps = coarse.sample_steps(w);
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> coarse_jacobian;
  coarse.evaluate(w, f, &coarse_jacobian);
  const std::vector<Eigen::MatrixXd> fine = jacobian != nullptr ? *jacobian : equations.contact_jacobian(w);
  out.correction.resize(fine.size());
  for (std::size_t p = 0; p < fine.size(); ++p) {
    out.correction[p] = fine[p] - coarse_jacobian[p];
    if (!out.correction[p].allFinite()) throw NumericalError("the coarse memory's contact Jacobian is not finite");
  }
  return out;
}

double FloquetResult::spectral_radius(double frequency_hz) const { return std::exp(max_real / frequency_hz); }

FloquetResult floquet_exponents(ReducedEquations& equations, const Eigen::VectorXd& w, double frequency_hz,
                                ExponentSelection selection, int max_size, double mode_cutoff,
                                const ContactMemory* memory) {
  return floquet_exponents(equations.linear_part(), equations.pair_layout(), equations.contact_jacobian(w),
                           frequency_hz, selection, max_size, mode_cutoff, memory);
}

FloquetResult floquet_exponents(const frf::LinearPart& linear, const hbm::HarmonicLayout& layout,
                                const std::vector<Eigen::MatrixXd>& blocks, double frequency_hz,
                                ExponentSelection selection, int max_size, double mode_cutoff,
                                const ContactMemory* memory) {
  FloquetResult out;
  if (memory != nullptr && !memory->carries_memory()) memory = nullptr;  // dF/dW is exact
  const int h = layout.n_harmonics(), nd = layout.n_directions(), pairs = static_cast<int>(blocks.size());
  const int c = linear.n_contact(), nk = 2 * h + 1, ne = c * nk;
  const double omega = kTwoPi * frequency_hz;
  // Modal forms keep the modes up to mode_cutoff (H + 1) w in the Hill problem (the others enter
  // R with their receptance at each harmonic: exact at lambda = 0); other forms keep everything.
  const double max_omega = mode_cutoff * (h + 1) * omega;

  out.families = linear.perturbation_families();
  std::vector<std::vector<frf::SecondOrderForm>> forms(out.families.size());
  for (std::size_t f = 0; f < out.families.size(); ++f) {
    forms[f].resize(static_cast<std::size_t>(nk));
    for (int k = -h; k <= h; ++k)
      if (!linear.perturbation_form(out.families[f], k, omega, max_omega, forms[f][static_cast<std::size_t>(k + h)])) {
        out.reason =
            "the linear part has no second-order form (lumped models and FE sectors have one) "
            "(docs/physics.md section 9)";
        return out;
      }
  }
  if (out.families.empty()) {
    out.reason =
        "no perturbation family has modes in all its blocks: an FE sector needs the modes of harmonic index 0 and "
        "of every index p + k m its blocks reach (docs/physics.md section 9)";
    return out;
  }
  // The sizes first: a point too large is not analysed, whatever else.
  std::vector<std::vector<Eigen::Index>> offsets(out.families.size());
  for (std::size_t f = 0; f < out.families.size(); ++f) {
    std::vector<Eigen::Index>& offset = offsets[f];
    offset.assign(static_cast<std::size_t>(nk + 1), 0);
    for (int k = -h; k <= h; ++k)
      offset[static_cast<std::size_t>(k + h + 1)] =
          offset[static_cast<std::size_t>(k + h)] + forms[f][static_cast<std::size_t>(k + h)].M.rows();
    out.hill_size = std::max(out.hill_size, static_cast<int>(2 * offset.back()));
  }
  if (memory != nullptr) {
    const int slider_unknowns = static_cast<int>(memory->pairs.size()) *
                                contact::n_tangential_directions(memory->model) *
                                static_cast<int>(memory->steps.front().size());
    out.hill_size += slider_unknowns;
    if (out.hill_size > kMaxSliderStateSize) {
      out.reason = "the Hill eigenproblem with the slider as a state would be " + std::to_string(out.hill_size) +
                   " wide (twice the second-order unknowns of the 2H + 1 harmonics, plus " +
                   std::to_string(slider_unknowns) + " damper positions: pairs x tangential directions x N), above " +
                   std::to_string(kMaxSliderStateSize) + " (forced/stability.hpp kMaxSliderStateSize)";
      return out;
    }
  } else if (out.hill_size > max_size) {
    out.reason = "the Hill eigenproblem would be " + std::to_string(out.hill_size) +
                 " wide (twice the second-order unknowns of the 2H + 1 harmonics), above " + std::to_string(max_size) +
                 " (forced/stability.hpp kMaxHillSize)";
    return out;
  }
  const bool massless = std::any_of(forms.begin(), forms.end(), [](const auto& family) {
    return std::any_of(family.begin(), family.end(), [](const auto& f) { return f.R.size() > 0 && !f.R.isZero(0.0); });
  });
  if (massless && ne > kMaxCondensedSize) {
    out.reason = "the contact condensation of the massless part would be " + std::to_string(ne) +
                 " wide (3 pairs x (2H + 1)), above " + std::to_string(kMaxCondensedSize) +
                 " (forced/stability.hpp kMaxCondensedSize)";
    return out;
  }
  out.available = true;
  out.selection = selection;

  // D in exponential coefficients: index (k + H) c + 3 p + d. Per pair and direction, the real
  // coefficients [c0 | c1 s1 | ...] map to X_0 = c0, X_n = (c_n - i s_n) / 2,
  // X_-n = (c_n + i s_n) / 2, and back c_n = X_n + X_-n, s_n = i (X_n - X_-n). The map is
  // complex-linear, so it also holds for a family's complex perturbation.
  const int b = layout.size();
  Eigen::MatrixXcd t = Eigen::MatrixXcd::Zero(b, b), t_inv = Eigen::MatrixXcd::Zero(b, b);
  const Complex i1(0.0, 1.0);
  for (int d = 0; d < nd; ++d) {
    auto row = [&](int k) { return d * nk + k + h; };  // local exponential index
    t(row(0), layout.index(d, 0)) = 1.0;
    t_inv(layout.index(d, 0), row(0)) = 1.0;
    for (int n = 1; n <= h; ++n) {
      const int ic = layout.index(d, n, hbm::HarmonicLayout::Part::cosine);
      const int is = layout.index(d, n, hbm::HarmonicLayout::Part::sine);
      t(row(n), ic) = 0.5, t(row(n), is) = -0.5 * i1;
      t(row(-n), ic) = 0.5, t(row(-n), is) = 0.5 * i1;
      t_inv(ic, row(n)) = 1.0, t_inv(ic, row(-n)) = 1.0;
      t_inv(is, row(n)) = i1, t_inv(is, row(-n)) = -i1;
    }
  }
  // With the slider as a state the law's steps replace it, but for the coarse memory's
  // correction (ContactMemory::correction), which enters the same way.
  const std::vector<Eigen::MatrixXd>* d_blocks = memory == nullptr ? &blocks : &memory->correction;
  const bool with_dx = memory == nullptr || !memory->correction.empty();
  Eigen::MatrixXcd dx = Eigen::MatrixXcd::Zero(with_dx ? ne : 0, with_dx ? ne : 0);
  for (int p = 0; with_dx && p < pairs; ++p) {
    const Eigen::MatrixXcd local = t * (*d_blocks)[static_cast<std::size_t>(p)].cast<Complex>() * t_inv;
    for (int d1 = 0; d1 < nd; ++d1)
      for (int k1 = -h; k1 <= h; ++k1)
        for (int d2 = 0; d2 < nd; ++d2)
          for (int k2 = -h; k2 <= h; ++k2)
            dx((k1 + h) * c + 3 * p + d1, (k2 + h) * c + 3 * p + d2) = local(d1 * nk + k1 + h, d2 * nk + k2 + h);
  }
  // Hill problems are a few hundred wide: OpenBLAS's threads inside LAPACK cost more than they
  // save there (stress model 7, Hill size 190: 76 s threaded against 21 s serial on a busy
  // 2-core machine).
  const linalg::SerialBlasScope serial;

  struct Chosen {
    Complex mu;
    int family;
  };
  std::vector<Chosen> chosen;
  for (std::size_t f = 0; f < out.families.size(); ++f) {
    auto form = [&](int k) -> const frf::SecondOrderForm& { return forms[f][static_cast<std::size_t>(k + h)]; };
    const std::vector<Eigen::Index>& offset = offsets[f];
    const Eigen::Index s = offset.back();
    if (s == 0) continue;  // every mode of the family quasi-static: no exponent
    // Phi = blockdiag(P_k); A0, A1, A2 over the modal unknowns, scaled by w (mu = lambda / w).
    Eigen::MatrixXcd phi = Eigen::MatrixXcd::Zero(ne, s);
    Eigen::MatrixXcd a0 = Eigen::MatrixXcd::Zero(s, s), a1 = Eigen::MatrixXcd::Zero(s, s);
    Eigen::MatrixXd a2 = Eigen::MatrixXd::Zero(s, s);
    for (int k = -h; k <= h; ++k) {
      const frf::SecondOrderForm& fk = form(k);
      const Eigen::Index o = offset[static_cast<std::size_t>(k + h)], m = fk.M.rows();
      if (m == 0) continue;
      phi.block((k + h) * c, o, c, m) = fk.P;
      const double kw = k * omega;
      a0.block(o, o, m, m) =
          (fk.K.cast<Complex>() + i1 * kw * fk.C.cast<Complex>() - kw * kw * fk.M.cast<Complex>()) / (omega * omega);
      a1.block(o, o, m, m) = (fk.C.cast<Complex>() + 2.0 * i1 * kw * fk.M.cast<Complex>()) / omega;
      a2.block(o, o, m, m) = fk.M;
    }
    const bool vectors = selection == ExponentSelection::symmetry;
    linalg::DenseEigen solver;
    if (memory != nullptr) {
      // The slider as a state: the pencil over [q; mu q; sigma].
      std::vector<const Eigen::MatrixXcd*> r(static_cast<std::size_t>(nk), nullptr);
      for (int k = -h; k <= h; ++k)
        if (form(k).R.size() > 0 && !form(k).R.isZero(0.0)) r[static_cast<std::size_t>(k + h)] = &form(k).R;
      solver = pencil_eigen(slider_state_pencil(a0, a1, a2, phi, r, h, c, nd, omega, *memory, dx));
    } else {
      // E = D (I + R D)^-1 = (I + D R)^-1 D, R block diagonal over k.
      Eigen::MatrixXcd dr = Eigen::MatrixXcd::Zero(ne, ne);
      bool with_r = false;
      for (int k = -h; k <= h; ++k) {
        const Eigen::MatrixXcd& r = form(k).R;
        if (r.size() == 0 || r.isZero(0.0)) continue;
        with_r = true;
        dr.middleCols((k + h) * c, c) = dx.middleCols((k + h) * c, c) * r;
      }
      Eigen::MatrixXcd e = dx;
      if (with_r) e = (Eigen::MatrixXcd::Identity(ne, ne) + dr).partialPivLu().solve(dx);
      a0 += phi.adjoint() * e * phi / (omega * omega);
      // Companion form: [0 I; -A2^-1 A0  -A2^-1 A1] [q; mu q] = mu [q; mu q].
      const Eigen::PartialPivLU<Eigen::MatrixXcd> a2_lu(a2.cast<Complex>());
      Eigen::MatrixXcd companion = Eigen::MatrixXcd::Zero(2 * s, 2 * s);
      companion.topRightCorner(s, s).setIdentity();
      companion.bottomLeftCorner(s, s) = -a2_lu.solve(a0);
      companion.bottomRightCorner(s, s) = -a2_lu.solve(a1);
      if (!companion.allFinite()) throw NumericalError("the Hill matrix is not finite");
      solver = hill_eigen(companion, offset, h, vectors);
    }
    const Eigen::VectorXcd& mu = solver.values;
    const int family = out.families[f];
    if (selection == ExponentSelection::symmetry) {
      for (Eigen::Index j = 0; j < mu.size(); ++j) {
        const auto q = solver.vectors.col(j).head(s);
        double total = 0.0, moment = 0.0;
        for (int k = -h; k <= h; ++k) {
          const Eigen::Index o = offset[static_cast<std::size_t>(k + h)];
          // Weighted by the block's mass (kinetic-energy-like, q_k^H M_k q_k): the same centroid
          // in any coordinates (modal, M = I, or physical), so a sector's families and the full
          // wheel keep the same exponents (tests/forced/test_cyclic_stability.cpp).
          const auto qk = q.segment(o, offset[static_cast<std::size_t>(k + h + 1)] - o);
          const double wk = (qk.adjoint() * form(k).M.cast<Complex>() * qk).real()(0, 0);
          total += wk;
          moment += k * wk;
        }
        if (memory != nullptr) {
          const auto sigma = solver.vectors.col(j).tail(solver.vectors.rows() - 2 * s);
          if ((phi * q).norm() < kSliderOnly * sigma.norm()) continue;
        }
        if (total > 0.0 && std::abs(moment / total) <= kCentroidHalfWidth) chosen.push_back({mu[j], family});
      }
    } else {
      std::vector<Complex> all(mu.data(), mu.data() + mu.size());
      std::sort(all.begin(), all.end(), [](Complex a, Complex b) { return std::abs(a.imag()) < std::abs(b.imag()); });
      const std::size_t keep = std::min(all.size(), static_cast<std::size_t>(2 * form(0).M.rows()));
      for (std::size_t j = 0; j < keep; ++j) chosen.push_back({all[j], family});
    }
  }
  if (chosen.empty()) throw NumericalError("no Floquet exponent selected");
  std::stable_sort(chosen.begin(), chosen.end(),
                   [](const Chosen& a, const Chosen& b) { return a.mu.real() > b.mu.real(); });
  for (const Chosen& m : chosen) {
    out.exponents.push_back(m.mu * omega);
    out.exponent_family.push_back(m.family);
  }
  out.max_real = out.exponents.front().real();
  out.stable = chosen.front().mu.real() <= kNeutralTolerance;
  return out;
}

std::string to_string(StabilityChange::Kind kind) {
  switch (kind) {
    case StabilityChange::Kind::fold: return "fold";
    case StabilityChange::Kind::period_doubling: return "period_doubling";
    case StabilityChange::Kind::neimark_sacker: return "neimark_sacker";
    case StabilityChange::Kind::unresolved: return "unresolved";
  }
  return "fold";
}

std::vector<StabilityChange> stability_changes(const std::vector<FloquetResult>& stability,
                                               const std::vector<double>& frequency_hz,
                                               const std::vector<double>& amplitude_m, const std::vector<int>& piece) {
  std::vector<StabilityChange> out;
  // Each judged point with the next judged point of its piece (points not judged between them
  // are skipped: the change lies somewhere between the two).
  for (std::size_t i = 0; i + 1 < stability.size(); ++i) {
    if (!stability[i].available) continue;
    std::size_t next = i + 1;
    while (next < stability.size() && !stability[next].available && piece[next] == piece[i]) ++next;
    if (next == stability.size()) break;
    const FloquetResult &a = stability[i], &b = stability[next];
    if (a.stable == b.stable || piece[i] != piece[next]) continue;
    const FloquetResult& unstable = a.stable ? b : a;
    const double w = kTwoPi * (a.stable ? frequency_hz[next] : frequency_hz[i]);
    StabilityChange c;
    c.point = i;
    double t = 0.5;
    if (a.exponents.empty() || b.exponents.empty()) {
      // A verdict without exponents (the shooting's march left the solution): kind and place unknown.
      c.kind = StabilityChange::Kind::unresolved;
    } else {
      const double im = std::abs(unstable.exponents.front().imag()) / w;
      c.kind = im < kKindTolerance                   ? StabilityChange::Kind::fold
               : std::abs(im - 0.5) < kKindTolerance ? StabilityChange::Kind::period_doubling
                                                     : StabilityChange::Kind::neimark_sacker;
      // Where max_real / w crosses zero, linearly between the two points.
      const double ra = a.max_real / (kTwoPi * frequency_hz[i]), rb = b.max_real / (kTwoPi * frequency_hz[next]);
      t = ra == rb ? 0.5 : std::clamp(ra / (ra - rb), 0.0, 1.0);
    }
    c.frequency_hz = frequency_hz[i] + t * (frequency_hz[next] - frequency_hz[i]);
    c.amplitude_m = amplitude_m[i] + t * (amplitude_m[next] - amplitude_m[i]);
    out.push_back(c);
  }
  return out;
}

}  // namespace shroudsim::forced
