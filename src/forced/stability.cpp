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
// Half a harmonic: the symmetric copy's eigenvector centroid lies within it.
constexpr double kCentroidHalfWidth = 0.5;
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
}  // namespace

double FloquetResult::spectral_radius(double frequency_hz) const { return std::exp(max_real / frequency_hz); }

FloquetResult floquet_exponents(ReducedEquations& equations, const Eigen::VectorXd& w, double frequency_hz,
                                ExponentSelection selection, int max_size, double mode_cutoff) {
  return floquet_exponents(equations.linear_part(), equations.pair_layout(), equations.contact_jacobian(w),
                           frequency_hz, selection, max_size, mode_cutoff);
}

FloquetResult floquet_exponents(const frf::LinearPart& linear, const hbm::HarmonicLayout& layout,
                                const std::vector<Eigen::MatrixXd>& blocks, double frequency_hz,
                                ExponentSelection selection, int max_size, double mode_cutoff) {
  FloquetResult out;
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
  if (out.hill_size > max_size) {
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
  Eigen::MatrixXcd dx = Eigen::MatrixXcd::Zero(ne, ne);
  for (int p = 0; p < pairs; ++p) {
    const Eigen::MatrixXcd local = t * blocks[static_cast<std::size_t>(p)].cast<Complex>() * t_inv;
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
    a0 += phi.adjoint() * e * phi / (omega * omega);
    // Companion form: [0 I; -A2^-1 A0  -A2^-1 A1] [q; mu q] = mu [q; mu q].
    const Eigen::PartialPivLU<Eigen::MatrixXcd> a2_lu(a2.cast<Complex>());
    Eigen::MatrixXcd companion = Eigen::MatrixXcd::Zero(2 * s, 2 * s);
    companion.topRightCorner(s, s).setIdentity();
    companion.bottomLeftCorner(s, s) = -a2_lu.solve(a0);
    companion.bottomRightCorner(s, s) = -a2_lu.solve(a1);
    if (!companion.allFinite()) throw NumericalError("the Hill matrix is not finite");
    const bool vectors = selection == ExponentSelection::symmetry;
    const linalg::DenseEigen solver = hill_eigen(companion, offset, h, vectors);
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
