// Shift-invert Lanczos (Spectra + CHOLMOD) against dense reference spectra; the complex
// 2n embedding returns each mode once, mass-normalised; failures are reported.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>

#include <fstream>
#include <iterator>
#include <thread>
#include <vector>

#include <Eigen/Eigenvalues>
#include <filesystem>

#include "cyclic/cyclic_sector.hpp"
#include "fe/assembly.hpp"
#include "fe/structured_mesh.hpp"
#include "modal/cache.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::modal {
namespace {

const fe::Material kSteel{210e9, 0.3, 7850.0};

// A bladed sector large enough for the Lanczos path (n_reduced > 300), small enough for a
// dense reference.
const cyclic::CyclicSector& bladed_sector() {
  static const mesh::Mesh m = [] {
    fe::AnnularSectorSpec s;
    s.sectors = 8;
    s.n_r = 2, s.n_theta = 3, s.n_z = 1, s.element_order = 2;
    s.r_inner = 0.1, s.r_outer = 0.16, s.thickness = 0.03;
    s.blade_length = 0.2, s.n_blade = 6;
    return fe::annular_sector_mesh(s);
  }();
  static const cyclic::CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  return sector;
}

Eigen::VectorXd dense_frequencies(const cyclic::CyclicSector& sector, int h) {
  const auto km = sector.reduce(h);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXcd> es(Eigen::MatrixXcd(km.K), Eigen::MatrixXcd(km.M),
                                                                Eigen::EigenvaluesOnly);
  return es.eigenvalues().cwiseSqrt();
}

class BothMethods : public ::testing::TestWithParam<EigenMethod> {};

TEST_P(BothMethods, LanczosMatchesDenseForEveryHarmonicIndexAndReturnsEachModeOnce) {
  const auto& sector = bladed_sector();
  ASSERT_GT(sector.n_reduced(), 300);  // the iterative path, not the dense fallback
  ModalOptions options;
  options.modes = 12;
  options.method = GetParam();
  const bool spectra = GetParam() == EigenMethod::Spectra;
  // Converged Lanczos frequencies agree with dense LAPACK-style ones to ~1e-12; 1e-8 is the
  // figure issue 3 asks of the cyclic spectra.
  constexpr double kRelTol = 1e-8;
  std::vector<Eigen::VectorXd> omega(sector.sectors());
  for (int h = 0; h < sector.sectors(); ++h) {
    const ModalResult r = solve_harmonic(sector, h, options);
    ASSERT_TRUE(r.report.ok()) << "h " << h << ": " << r.report.message;
    if (spectra) EXPECT_EQ(r.report.method, sector.is_real(h) ? "spectra-real" : "spectra-complex-2n");
    else EXPECT_EQ(r.report.method, sector.is_real(h) ? "block-real" : "block-complex");
    ASSERT_EQ(r.basis.size(), options.modes);
    EXPECT_EQ(r.basis.harmonic_index, h);
    const Eigen::VectorXd ref = dense_frequencies(sector, h).head(options.modes);
    for (int j = 0; j < options.modes; ++j)
      EXPECT_NEAR(r.basis.omega(j), ref(j), kRelTol * ref(j)) << "h " << h << " mode " << j;
    // Mass-normalised and M-orthogonal: no mode returned twice (a duplicate z, i z would
    // give an off-diagonal entry of modulus 1).
    const auto km = sector.reduce(h);
    const Eigen::MatrixXcd G = r.basis.phi.adjoint() * (km.M * r.basis.phi);
    EXPECT_LT((G - Eigen::MatrixXcd::Identity(options.modes, options.modes)).norm(), 1e-8) << "h " << h;
    EXPECT_LE(r.report.max_residual, options.residual_tolerance);
    // ND 0 and Nb/2 modes are real.
    if (sector.is_real(h)) EXPECT_EQ(r.basis.phi.imag().norm(), 0.0);
    else EXPECT_GT(r.basis.phi.imag().norm(), 0.1);
    omega[h] = r.basis.omega;
  }
  // h and Nb - h, solved independently: equal frequencies.
  for (int h = 1; h < sector.sectors(); ++h)
    for (int j = 0; j < options.modes; ++j)
      EXPECT_NEAR(omega[h](j), omega[sector.sectors() - h](j), kRelTol * omega[h](j));
}

INSTANTIATE_TEST_SUITE_P(Eigensolvers, BothMethods, ::testing::Values(EigenMethod::Block, EigenMethod::Spectra),
                         [](const auto& info) { return to_string(info.param); });

TEST(SolveHarmonic, BlockAndSpectraGiveTheSameModes) {
  // Independent methods (block Krylov-Schur in complex arithmetic; Spectra's Lanczos on the
  // real 2n embedding): equal frequencies and the same mode shapes up to a unit factor.
  const auto& sector = bladed_sector();
  ModalOptions a, b;
  a.modes = b.modes = 10;
  b.method = EigenMethod::Spectra;
  for (int h : {0, 1, 3, 4}) {
    const ModalResult ra = solve_harmonic(sector, h, a), rb = solve_harmonic(sector, h, b);
    ASSERT_TRUE(ra.report.ok() && rb.report.ok()) << h;
    const auto km = sector.reduce(h);
    // |phi_a^H M phi_b| = 1 for the same (simple) mode; frequencies to 1e-9 (both are
    // converged to 1e-10 on the shift-invert Ritz values).
    const Eigen::MatrixXcd C = ra.basis.phi.adjoint() * (km.M * rb.basis.phi);
    for (int j = 0; j < a.modes; ++j) {
      EXPECT_NEAR(ra.basis.omega(j), rb.basis.omega(j), 1e-9 * ra.basis.omega(j)) << "h " << h << " mode " << j;
      EXPECT_NEAR(std::abs(C(j, j)), 1.0, 1e-6) << "h " << h << " mode " << j;
    }
  }
}

// The 5-point Laplacian of an N x N grid (Dirichlet), with the phase e^{i theta} on every
// x-bond: Hermitian, and gauge-equivalent to the real Laplacian, so its eigenvalues are
// 4 - 2 cos(i pi/(N+1)) - 2 cos(j pi/(N+1)) for 1 <= i, j <= N; (i, j) and (j, i) give
// eigenvalues of multiplicity two.
template <typename S>
linalg::SparsePair<S> grid_laplacian(int N, double theta) {
  std::vector<Eigen::Triplet<S>> t;
  auto id = [N](int i, int j) { return i * N + j; };
  S phase = S(1);
  if constexpr (!std::is_same_v<S, double>) phase = std::polar(1.0, theta);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      t.emplace_back(id(i, j), id(i, j), S(4));
      if (i + 1 < N) {
        t.emplace_back(id(i, j), id(i + 1, j), -phase);
        t.emplace_back(id(i + 1, j), id(i, j), -Eigen::numext::conj(phase));
      }
      if (j + 1 < N) {
        t.emplace_back(id(i, j), id(i, j + 1), S(-1));
        t.emplace_back(id(i, j + 1), id(i, j), S(-1));
      }
    }
  linalg::SparsePair<S> km;
  km.K.resize(N * N, N * N);
  km.K.setFromTriplets(t.begin(), t.end());
  km.M.resize(N * N, N * N);
  km.M.setIdentity();
  km.K.makeCompressed();
  km.M.makeCompressed();
  return km;
}

template <typename S>
void expect_grid_spectrum(int N, int modes, EigenMethod method) {
  std::vector<double> exact;
  for (int i = 1; i <= N; ++i)
    for (int j = 1; j <= N; ++j)
      exact.push_back(4 - 2 * std::cos(i * M_PI / (N + 1)) - 2 * std::cos(j * M_PI / (N + 1)));
  std::sort(exact.begin(), exact.end());
  ModalOptions o;
  o.modes = modes;
  o.method = method;
  const ModalResult r = solve_modes(grid_laplacian<S>(N, 0.7), 0, o);
  ASSERT_TRUE(r.report.ok()) << r.report.message;
  ASSERT_EQ(r.basis.size(), modes);
  for (int k = 0; k < modes; ++k)
    EXPECT_NEAR(r.basis.omega(k) * r.basis.omega(k), exact[k], 1e-9 * exact[k]) << "eigenvalue " << k;
}

TEST(BlockEigensolver, FindsBothCopiesOfDoubleEigenvaluesRealAndComplex) {
  // 24 of the lowest 30 eigenvalues of the 40 x 40 grid are double.
  expect_grid_spectrum<double>(40, 30, EigenMethod::Block);
  expect_grid_spectrum<Complex>(40, 30, EigenMethod::Block);
}

TEST(SolveHarmonic, ConjugateBasisSolvesHarmonicIndexNbMinusH) {
  const auto& sector = bladed_sector();
  ModalOptions options;
  options.modes = 5;
  const ModalResult r = solve_harmonic(sector, 3, options);
  ASSERT_TRUE(r.report.ok());
  const ModalBasis b = r.basis.conjugate(5);
  const auto km = sector.reduce(5);
  for (int j = 0; j < b.size(); ++j) {
    const Eigen::VectorXcd res = km.K * b.phi.col(j) - b.omega(j) * b.omega(j) * (km.M * b.phi.col(j));
    EXPECT_LT(res.norm(), 1e-6 * (km.K * b.phi.col(j)).norm());
  }
}

TEST(SolveHarmonic, KeptStiffnessFactorSolvesKh) {
  const auto& sector = bladed_sector();
  ModalOptions options;
  options.modes = 3;
  for (int h : {0, 2}) {
    const ModalResult r = solve_harmonic(sector, h, options);
    ASSERT_TRUE(r.report.ok());
    ASSERT_TRUE(r.stiffness.valid());  // shift 0: the factor of K_h itself
    std::srand(5);
    const Eigen::MatrixXcd f = Eigen::MatrixXcd::Random(sector.n_reduced(), 2);
    const auto km = sector.reduce(h);
    for (const StiffnessFactor& fac : {r.stiffness, factor_harmonic_stiffness(sector, h)}) {
      const Eigen::MatrixXcd x = fac.solve(f);
      EXPECT_LT((km.K * x - f).norm(), 1e-9 * f.norm()) << h;
    }
    // Nb - h through the conjugated factor.
    const auto kmc = sector.reduce((sector.sectors() - h) % sector.sectors());
    const Eigen::MatrixXcd xc = r.stiffness.conjugate().solve(f);
    EXPECT_LT((kmc.K * xc - f).norm(), 1e-9 * f.norm()) << h;
  }
}

TEST(SolveHarmonic, OneSharedAnalysisGivesTheModesOfAFreshAnalysisBitForBit) {
  // Every K_h of the sector has one pattern; one symbolic analysis (made from a complex
  // index) serves the real and the complex solves. CHOLMOD's analysis reads the pattern
  // only, so the factors, and with them the modes, must be identical to the last bit.
  const auto& sector = bladed_sector();
  ModalOptions fresh, shared;
  fresh.modes = shared.modes = 6;
  shared.analysis = analyse_pattern(sector.reduce(2), 0.0, shared.factor_method);
  ASSERT_TRUE(shared.analysis && shared.analysis->symbolic);
  EXPECT_EQ(shared.analysis->rows, sector.n_reduced());
  for (int h : {0, 1, 2, 4}) {
    const ModalResult a = solve_harmonic(sector, h, fresh), b = solve_harmonic(sector, h, shared);
    ASSERT_TRUE(a.report.ok() && b.report.ok()) << h;
    EXPECT_EQ(a.basis.omega, b.basis.omega) << h;
    EXPECT_EQ(a.basis.phi, b.basis.phi) << h;
    EXPECT_EQ(a.report.factor_nonzeros, b.report.factor_nonzeros) << h;
    // The kept stiffness factor solves K_h as well.
    ASSERT_TRUE(b.stiffness.valid());
    const Eigen::MatrixXcd f = Eigen::MatrixXcd::Ones(sector.n_reduced(), 1);
    const auto km = sector.reduce(h);
    EXPECT_LT((km.K * b.stiffness.solve(f) - f).norm(), 1e-9 * f.norm()) << h;
  }
}

TEST(HarmonicStiffnessFactors, OneSharedAnalysisGivesTheStaticSolutionsOfFreshFactorsBitForBit) {
  // The receptance and shape stages factor K_h of several harmonic indices on one analysis
  // (made by the first call, from several threads at once); the static solutions must be
  // those of a fresh factorization to the last bit, real indices (0, Nb/2) and complex ones.
  const auto& sector = bladed_sector();
  const HarmonicStiffnessFactors factors(sector, linalg::FactorMethod::Supernodal);
  const Eigen::MatrixXcd f = Eigen::MatrixXcd::Random(sector.n_reduced(), 3);
  std::vector<int> indices;
  for (int h = 0; h <= sector.sectors() / 2; ++h) indices.push_back(h);
  std::vector<Eigen::MatrixXcd> shared(indices.size());
  std::vector<std::thread> workers;
  for (std::size_t i = 0; i < indices.size(); ++i)
    workers.emplace_back([&, i]() { shared[i] = factors(indices[i]).solve(f); });
  for (auto& w : workers) w.join();
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const int h = indices[i];
    EXPECT_EQ(shared[i], factor_harmonic_stiffness(sector, h).solve(f)) << h;
    const auto km = sector.reduce(h);
    EXPECT_LT((km.K * shared[i] - f).norm(), 1e-9 * f.norm()) << h;
  }
}

TEST(CholmodFactor, AnalyzeLikeRefusesAFactorizedSource) {
  // A numeric factor is not a symbolic analysis: copying it would carry its values and its
  // scalar type into another factorization.
  const auto km = grid_laplacian<double>(6, 0.0);
  linalg::CholmodFactor<double> numeric;
  ASSERT_EQ(numeric.compute(km.K), linalg::FactorStatus::Success);
  EXPECT_FALSE(numeric.symbolic_only());
  linalg::CholmodFactor<Complex> target;
  EXPECT_THROW(target.analyze_like(numeric), std::exception);
}

TEST(SolveHarmonic, UnconvergedLanczosIsReportedNotReturned) {
  const auto& sector = bladed_sector();
  ModalOptions options;
  options.method = EigenMethod::Spectra;
  options.modes = 20;
  options.ncv = 45;          // barely above nev = 44 for the 2n problem
  options.max_restarts = 1;  // cannot converge 44 Ritz pairs in one sweep
  const ModalResult r = solve_harmonic(sector, 1, options);
  EXPECT_EQ(r.report.status, ModalStatus::NotConverged);
  EXPECT_FALSE(r.report.message.empty());
  EXPECT_EQ(r.basis.size(), 0);
}

TEST(SolveHarmonic, UnconvergedBlockIterationIsReportedNotReturned) {
  const auto& sector = bladed_sector();
  ModalOptions options;
  options.modes = 20;
  options.ncv = 28;          // basis of 7 blocks of 4 for 20 modes
  options.max_restarts = 1;  // two sweeps of the basis: not enough for 1e-10
  const ModalResult r = solve_harmonic(sector, 1, options);
  EXPECT_EQ(r.report.status, ModalStatus::NotConverged);
  EXPECT_NE(r.report.message.find("block Krylov-Schur"), std::string::npos) << r.report.message;
  EXPECT_EQ(r.basis.size(), 0);
}

TEST(SolveHarmonic, ShiftAboveTheFirstModeIsAFactorizationFailure) {
  const auto& sector = bladed_sector();
  ModalOptions options;
  options.modes = 3;
  const ModalResult ok = solve_harmonic(sector, 0, options);
  ASSERT_TRUE(ok.report.ok());
  options.shift = 4.0 * ok.basis.omega(0) * ok.basis.omega(0);  // K - sigma M indefinite
  const ModalResult r = solve_harmonic(sector, 0, options);
  EXPECT_EQ(r.report.status, ModalStatus::FactorizationFailed);
  EXPECT_EQ(r.basis.size(), 0);
}

TEST(ModalCache, RoundTripsBases) {
  const auto dir = std::filesystem::temp_directory_path() / "shroudsim_modal_cache_test";
  std::filesystem::remove_all(dir);
  std::string problem;
  ModalBasis b{3, Eigen::VectorXd::LinSpaced(4, 1.0, 4.0), Eigen::MatrixXcd::Random(7, 4)};
  save_basis(dir / "b.bin", "key-b", b);
  const auto bb = load_basis(dir / "b.bin", "key-b");
  ASSERT_TRUE(bb.has_value());
  EXPECT_EQ(bb->harmonic_index, 3);
  EXPECT_EQ((bb->omega - b.omega).norm(), 0.0);
  EXPECT_EQ((bb->phi - b.phi).norm(), 0.0);
  // Absent: nullopt and no problem. Another key, another kind: refused with a reason.
  problem.clear();
  EXPECT_FALSE(load_basis(dir / "missing.bin", "key-b", &problem).has_value());
  EXPECT_TRUE(problem.empty());
  EXPECT_FALSE(load_basis(dir / "b.bin", "key-other", &problem).has_value());
  EXPECT_FALSE(problem.empty());
  std::filesystem::remove_all(dir);
}

// A mesh entry gives back every field as it was written (the mesh stage's cache of read
// meshes, pipeline/mesh_stage.cpp), and only under its own key.
TEST(ModalCache, RoundTripsMeshes) {
  const auto dir = std::filesystem::temp_directory_path() / "shroudsim_mesh_cache_test";
  std::filesystem::remove_all(dir);
  mesh::Mesh m;
  m.nodes = mesh::NodeMatrix::Random(12, 3);
  m.tets.resize(2, 10);
  for (Eigen::Index i = 0; i < m.tets.size(); ++i) m.tets.data()[i] = static_cast<int>((7 * i + 3) % 12);
  m.element_order = 2;
  m.sectors = 7;
  m.node_sets = {{"hub", {0, 1, 2}}, {"shroud_low", {4, 5}}, {"shroud_high", {9, 11}}};
  m.surface_triangles["shroud_low"] = mesh::ConnectivityMatrix::Constant(1, 6, 5);
  m.surface_triangles["hub"] = mesh::ConnectivityMatrix::Constant(2, 6, 1);
  m.cyclic_pairs = {{0, 6}, {1, 7}};
  m.shroud_pairs = {{4, 9}, {5, 11}};
  save_mesh(dir / "m.bin", "key-m", m);
  const auto r = load_mesh(dir / "m.bin", "key-m");
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->nodes, m.nodes);
  EXPECT_EQ(r->tets, m.tets);
  EXPECT_EQ(r->element_order, 2);
  EXPECT_EQ(r->sectors, 7);
  EXPECT_EQ(r->node_sets, m.node_sets);
  ASSERT_EQ(r->surface_triangles.size(), 2u);
  for (const auto& [name, tri] : m.surface_triangles) EXPECT_EQ(r->surface_triangles.at(name), tri) << name;
  EXPECT_EQ(r->cyclic_pairs, m.cyclic_pairs);
  EXPECT_EQ(r->shroud_pairs, m.shroud_pairs);
  std::string problem;
  EXPECT_FALSE(load_mesh(dir / "m.bin", "key-other", &problem).has_value());
  EXPECT_FALSE(problem.empty());
  // A modes entry is not a mesh (another kind), nor the other way round.
  save_basis(dir / "b.bin", "key-m", ModalBasis{0, Eigen::VectorXd::Ones(1), Eigen::MatrixXcd::Ones(3, 1)});
  problem.clear();
  EXPECT_FALSE(load_mesh(dir / "b.bin", "key-m", &problem).has_value());
  EXPECT_FALSE(problem.empty());
  problem.clear();
  EXPECT_FALSE(load_basis(dir / "m.bin", "key-m", &problem).has_value());
  EXPECT_FALSE(problem.empty());
  std::filesystem::remove_all(dir);
}

// Any changed byte of an entry (at offsets spread over the header, the payload and the
// checksum) or a truncation is detected: never used, always with a reason.
TEST(ModalCache, CorruptedBytesAreDetectedAtEveryOffset) {
  const auto dir = std::filesystem::temp_directory_path() / "shroudsim_modal_cache_corrupt";
  std::filesystem::remove_all(dir);
  ModalBasis b{1, Eigen::VectorXd::LinSpaced(5, 1.0, 5.0), Eigen::MatrixXcd::Random(9, 5)};
  save_basis(dir / "b.bin", "k", b);
  int checked = 0;
  {
    const auto file = dir / "b.bin";
    std::string bytes;
    {
      std::ifstream in(file, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::size_t n = bytes.size();
    for (std::size_t k = 0; k < 64; ++k) {
      const std::size_t at = k * (n - 1) / 63;
      std::string bad = bytes;
      bad[at] = static_cast<char>(bad[at] ^ 0x5a);
      std::ofstream(file, std::ios::binary | std::ios::trunc) << bad;
      std::string problem;
      EXPECT_FALSE(load_basis(file, "k", &problem).has_value()) << "byte " << at;
      EXPECT_FALSE(problem.empty()) << "byte " << at;
      ++checked;
    }
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes.substr(0, n / 2);
    std::string problem;
    EXPECT_FALSE(load_basis(file, "k", &problem).has_value());
    EXPECT_FALSE(problem.empty());
  }
  EXPECT_EQ(checked, 64);
  std::filesystem::remove_all(dir);
}

// The cache folder is kept within its bound: after a write the least recently used entries go
// (a read is a use), never the entry just written nor a file that is not an entry; an
// interrupted write's leftover goes once it is an hour old, a write in progress stays.
TEST(ModalCache, IsTrimmedToItsLimitByLeastRecentUse) {
  namespace fs = std::filesystem;
  using std::chrono::minutes;
  const auto dir = fs::temp_directory_path() / ("shroudsim_cache_trim_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::uintmax_t limit_before = cache_limit();
  TaggedArrays a;
  a.tags = {0};
  a.vectors = {Eigen::VectorXd::Ones(12'500)};  // about 100 kB an entry
  auto name = [](int i) { return "receptances-000000000000000" + std::to_string(i) + ".bin"; };
  const auto now = fs::file_time_type::clock::now();
  set_cache_limit(std::uintmax_t{1} << 40);  // nothing trimmed while the folder is set up
  for (int i = 0; i < 4; ++i) {              // entries 0..3, last used 40, 30, 20, 10 minutes ago
    save_arrays(dir / name(i), "k", a);
    fs::last_write_time(dir / name(i), now - minutes(40 - 10 * i));
  }
  const std::uintmax_t entry = fs::file_size(dir / name(0));
  std::ofstream(dir / "notes.txt") << "not an entry";
  std::ofstream(dir / (name(7) + ".tmp123")) << "an interrupted write";
  fs::last_write_time(dir / (name(7) + ".tmp123"), now - minutes(120));
  std::ofstream(dir / (name(8) + ".tmp456")) << "a write in progress";
  ASSERT_TRUE(load_arrays(dir / name(0), "k").has_value());  // entry 0 used now
  // Room for three and a half entries: writing a fifth deletes the two least recently used.
  set_cache_limit(3 * entry + entry / 2);
  save_arrays(dir / name(4), "k", a);
  EXPECT_TRUE(fs::exists(dir / name(0)));
  EXPECT_FALSE(fs::exists(dir / name(1)));
  EXPECT_FALSE(fs::exists(dir / name(2)));
  EXPECT_TRUE(fs::exists(dir / name(3)));
  EXPECT_TRUE(fs::exists(dir / name(4)));
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_FALSE(fs::exists(dir / (name(7) + ".tmp123")));
  EXPECT_TRUE(fs::exists(dir / (name(8) + ".tmp456")));
  // A bound below one entry keeps only the entry just written.
  set_cache_limit(0);
  save_arrays(dir / name(5), "k", a);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.path().extension() == ".bin";
  EXPECT_EQ(entries, 1);
  EXPECT_TRUE(fs::exists(dir / name(5)));
  set_cache_limit(limit_before);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace shroudsim::modal
