// Timing of the linear modal pipeline on one sector: assembly, cyclic reduction, CHOLMOD
// factorization and Spectra shift-invert Lanczos per harmonic index, peak memory.
//
// usage: modal_benchmark [--msh FILE] [--structured N_R N_THETA N_Z N_BLADE]
//                        [--sectors NB] [--modes M] [--threads T] [--parallel] [--label TEXT]
//                        [--only-h H] [--method block|spectra] [--block B] [--ncv M]
//  --msh         a sector mesh (.msh, as written by `shroudsim mesh`)
//  --structured  the structured disk-and-blade sector of fe/structured_mesh.hpp (10-node)
//  --parallel    also time all harmonic indices solved by T workers (as `shroudsim modes` does)
// Prints one line per harmonic index and a markdown table row for BENCHMARKS.md.
// Harmonic indices h > Nb/2 are not solved: their modes are the conjugates of Nb - h.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

#include "core/allocator.hpp"
#include "core/log.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "fe/assembly.hpp"
#include "fe/structured_mesh.hpp"
#include "modal/harmonic.hpp"
#ifdef SHROUDSIM_HAVE_MSH_READER
#include "mesh/msh_reader.hpp"
#endif
#include "linalg/blas.hpp"
#include "linalg/cholmod_factor.hpp"

using namespace shroudsim;

int main(int argc, char** argv) {
  core::configure_allocator();               // as the program does
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress visible when redirected
  std::string msh, label = "sector";
  fe::AnnularSectorSpec spec;
  spec.sectors = 8;
  spec.r_inner = 0.10, spec.r_outer = 0.16, spec.thickness = 0.03, spec.blade_length = 0.25;
  spec.n_r = 4, spec.n_theta = 6, spec.n_z = 2, spec.n_blade = 12;
  int modes = 30, threads = 1;
  bool parallel = false;
  int only_h = -1, block = 0, ncv = 0;
  std::string method = "block";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--msh" && i + 1 < argc) msh = argv[++i];
    else if (a == "--structured" && i + 4 < argc) {
      spec.n_r = std::atoi(argv[++i]);
      spec.n_theta = std::atoi(argv[++i]);
      spec.n_z = std::atoi(argv[++i]);
      spec.n_blade = std::atoi(argv[++i]);
    } else if (a == "--sectors" && i + 1 < argc) spec.sectors = std::atoi(argv[++i]);
    else if (a == "--modes" && i + 1 < argc) modes = std::atoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (a == "--parallel") parallel = true;
    else if (a == "--label" && i + 1 < argc) label = argv[++i];
    else if (a == "--only-h" && i + 1 < argc) only_h = std::atoi(argv[++i]);
    else if (a == "--method" && i + 1 < argc) method = argv[++i];
    else if (a == "--block" && i + 1 < argc) block = std::atoi(argv[++i]);
    else if (a == "--ncv" && i + 1 < argc) ncv = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: modal_benchmark [--msh FILE] [--structured NR NT NZ NB] [--sectors NB] "
                   "[--modes M] [--threads T] [--parallel] [--label TEXT] [--only-h H] "
                   "[--method block|spectra] [--block B] [--ncv M]\n");
      return 2;
    }
  }
  mesh::Mesh m;
  if (!msh.empty()) {
#ifdef SHROUDSIM_HAVE_MSH_READER
    m = mesh::read_sector_mesh(msh, {spec.sectors, 1e-6});
    m.sectors = spec.sectors;
#else
    std::fprintf(stderr, "modal_benchmark: built without the .msh reader\n");
    return 2;
#endif
  } else {
    m = fe::annular_sector_mesh(spec);
  }
  const int nb = m.sectors;
  std::printf("%s: %d nodes, %d %d-node tets, %d DOFs, Nb = %d, %d modes per harmonic index\n", label.c_str(),
              m.n_nodes(), m.n_elements(), m.nodes_per_element(), m.n_dofs(), nb, modes);

  const fe::Material steel{210e9, 0.3, 7850.0};
  log::Stopwatch watch;
  const fe::Assembler assembler(m);
  const double pattern_s = watch.seconds();
  watch.restart();
  const auto km = assembler.assemble(steel, threads);
  const double values_s = watch.seconds();
  watch.restart();
  const cyclic::CyclicSector sector(m, km);
  const double cyclic_s = watch.seconds();
  std::printf(
      "  assembly: pattern %.3f s + values %.3f s (%d threads), %ld stored entries; cyclic setup %.3f s; "
      "%ld reduced DOFs\n",
      pattern_s, values_s, threads, static_cast<long>(km.K.nonZeros()), cyclic_s,
      static_cast<long>(sector.n_reduced()));

  modal::ModalOptions options;
  options.modes = modes;
  options.method = method == "spectra" ? modal::EigenMethod::Spectra : modal::EigenMethod::Block;
  options.block_size = block;
  options.ncv = ncv;
  std::vector<int> hs;
  for (int h = 0; 2 * h <= nb; ++h)
    if (only_h < 0 || h == only_h) hs.push_back(h);
  double total = 0.0, fac_real = 0, fac_cplx = 0, lan_real = 0, lan_cplx = 0;
  int n_real = 0, n_cplx = 0;
  for (int h : hs) {
    log::Stopwatch t;
    const auto r = modal::solve_harmonic(sector, h, options);
    const double s = t.seconds();
    total += s;
    const auto& rep = r.report;
    if (!rep.ok()) {
      std::printf("  h = %d FAILED: %s\n", h, rep.message.c_str());
      return 3;
    }
    std::printf(
        "  h = %d (%s): total %.2f s = reduce+check %.2f s, factor %.2f s (nnz(L) %.3g), eigensolver %.2f s "
        "(%d solves, %d M products, %d steps/restarts); f = %.2f .. %.2f Hz, max residual %.1e\n",
        h, rep.method.c_str(), s, s - rep.factor_seconds - rep.solve_seconds, rep.factor_seconds, rep.factor_nonzeros,
        rep.solve_seconds, rep.operations, rep.mass_products, rep.iterations, r.basis.frequency_hz()(0),
        r.basis.frequency_hz()(r.basis.size() - 1), rep.max_residual);
    if (sector.is_real(h)) fac_real += rep.factor_seconds, lan_real += rep.solve_seconds, ++n_real;
    else fac_cplx += rep.factor_seconds, lan_cplx += rep.solve_seconds, ++n_cplx;
  }
  // Where a factorization's time goes: the symbolic analysis (fill-reducing ordering,
  // supernodes) against the numeric factorization, for a real and a complex index.
  auto time_factor = [](const auto& K, auto factor, double& analysis, double& numeric) {
    log::Stopwatch t;
    factor.analyze(K);
    analysis = t.seconds();
    t.restart();
    factor.factorize(K);
    numeric = t.seconds();
  };
  for (int h : {0, 1}) {
    if (2 * h > nb) continue;
    double analysis = 0.0, numeric = 0.0;
    if (sector.is_real(h)) time_factor(sector.reduce_real(h).K, linalg::CholmodFactor<double>(), analysis, numeric);
    else time_factor(sector.reduce(h).K, linalg::CholmodFactor<linalg::Complex>(), analysis, numeric);
    std::printf("  h = %d factor: analysis %.2f s + numeric %.2f s\n", h, analysis, numeric);
  }
  double parallel_s = 0.0;
  if (parallel && threads > 1) {
    // One BLAS thread per worker (OpenBLAS threads on top of the workers oversubscribe the
    // cores: 171 s against 104 s sequential at 2e5 DOFs).
    const int blas_before = linalg::set_blas_threads(1);
    log::Stopwatch t;
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      for (std::size_t i = next++; i < hs.size(); i = next++) modal::solve_harmonic(sector, hs[i], options);
    };
    std::vector<std::thread> pool;
    for (int k = 1; k < threads; ++k) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
    parallel_s = t.seconds();
    if (blas_before > 0) linalg::set_blas_threads(blas_before);
  }
  const double peak = log::peak_memory_mib();
  std::printf("  all %d harmonic indices (%zu solves, conjugates for the rest): %.1f s sequential", nb, hs.size(),
              total);
  if (parallel_s > 0) std::printf(", %.1f s with %d workers", parallel_s, threads);
  std::printf("; peak memory %.0f MiB\n", peak);
  std::printf("| %s | %d | %ld | %.2f | %.2f / %.2f | %.1f / %.1f | %.1f | %s | %.0f |\n", label.c_str(), m.n_dofs(),
              static_cast<long>(sector.n_reduced()), pattern_s + values_s, n_real ? fac_real / n_real : 0.0,
              n_cplx ? fac_cplx / n_cplx : 0.0, n_real ? lan_real / n_real : 0.0, n_cplx ? lan_cplx / n_cplx : 0.0,
              total, parallel_s > 0 ? (std::to_string(static_cast<int>(parallel_s + 0.5)) + " s").c_str() : "-", peak);
  return 0;
}
