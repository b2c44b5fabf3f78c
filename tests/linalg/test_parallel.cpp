// linalg::parallel_for: every job, once; the BLAS on one thread whatever the worker count.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <atomic>
#include <cmath>
#include <vector>

#include "linalg/blas.hpp"
#include "linalg/cholmod_factor.hpp"
#include "linalg/parallel.hpp"

namespace shroudsim::linalg {
namespace {

TEST(ParallelFor, RunsEveryJobOnce) {
  for (int workers : {1, 2, 3}) {
    std::vector<std::atomic<int>> runs(7);
    parallel_for(7, workers, [&](int i) { ++runs[static_cast<std::size_t>(i)]; });
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1) << workers << " workers";
  }
}

// A factorization's round-off depends on the BLAS thread count: with one worker and a
// threaded BLAS the modes differed from those of two workers and a serial BLAS, and
// --threads 1 and 2 traced different curves (docs/continuation.md, "Determinism").
TEST(ParallelFor, RunsItsJobsOnAOneThreadBlasWhateverTheWorkerCount) {
  const int before = set_blas_threads(2);
  if (before == 0) GTEST_SKIP() << "the BLAS exposes no thread setting";
  const int outside = set_blas_threads(2);  // what the BLAS may use outside the jobs
  for (int workers : {1, 2}) {
    std::atomic<int> seen{-1};
    parallel_for(1, workers, [&](int) { seen = set_blas_threads(1); });  // returns the setting in force
    EXPECT_EQ(seen.load(), 1) << workers << " workers";
    EXPECT_EQ(set_blas_threads(2), outside) << "restored after the jobs";
  }
  set_blas_threads(before);
}

// With two or more workers, OpenMP regions a job opens (CHOLMOD's supernodal factorization opens
// teams of a fixed size) run on the job's thread alone, and the setting is the thread's own:
// the calling thread gets back what it had, and one worker does not change another's.
TEST(ParallelFor, RunsOpenMPRegionsOfItsJobsOnTheirOwnThreadWithTwoOrMoreWorkers) {
  using Get = int (*)();
  const auto get = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  if (!get) GTEST_SKIP() << "no OpenMP runtime loaded";
  const int outside = get();
  ASSERT_GT(outside, 0) << "nested regions allowed outside the jobs";
  for (int workers : {2, 3}) {
    std::vector<std::atomic<int>> seen(6);
    for (auto& v : seen) v = -1;
    parallel_for(6, workers, [&](int i) { seen[static_cast<std::size_t>(i)] = get(); });
    for (const auto& v : seen) EXPECT_EQ(v.load(), 0) << workers << " workers";
    EXPECT_EQ(get(), outside) << "restored on the calling thread";
  }
  // One worker: the caller's own setting (its regions may use the cores the pool leaves free).
  std::atomic<int> one{-1};
  parallel_for(1, 1, [&](int) { one = get(); });
  EXPECT_EQ(one.load(), outside);
}

// Factorizations on parallel workers are those of one thread to the last bit. CHOLMOD's ordering
// of a large 3D pattern tries nested dissection (METIS), whose random generator is global to
// the process: two analyses at once interleaved their draws, and the 77k-DOF sector's
// receptances differed between identical runs on two threads. The 3D Laplacian here is large
// enough for that ordering (26^3 unknowns).
TEST(ParallelFor, FactorizationsOnTwoWorkersAreThoseOfOneThread) {
  constexpr int g = 26;
  const auto id = [](int i, int j, int k) { return (i * g + j) * g + k; };
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j)
      for (int k = 0; k < g; ++k) {
        t.emplace_back(id(i, j, k), id(i, j, k), 6.01);
        if (i + 1 < g)
          t.emplace_back(id(i, j, k), id(i + 1, j, k), -1.0), t.emplace_back(id(i + 1, j, k), id(i, j, k), -1.0);
        if (j + 1 < g)
          t.emplace_back(id(i, j, k), id(i, j + 1, k), -1.0), t.emplace_back(id(i, j + 1, k), id(i, j, k), -1.0);
        if (k + 1 < g)
          t.emplace_back(id(i, j, k), id(i, j, k + 1), -1.0), t.emplace_back(id(i, j, k + 1), id(i, j, k), -1.0);
      }
  SparseMatrixD a(g * g * g, g * g * g);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  Eigen::VectorXd b(a.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * static_cast<double>(i));
  const auto solve = [&] {
    CholmodFactor<double> f;
    EXPECT_EQ(f.compute(a), FactorStatus::Success);
    return Eigen::VectorXd(f.solve(Eigen::MatrixXd(b)).col(0));
  };
  Eigen::VectorXd one;  // one worker: the BLAS on one thread, as in the jobs
  parallel_for(1, 1, [&](int) { one = solve(); });
  constexpr int kJobs = 8;
  std::vector<Eigen::VectorXd> x(kJobs);
  parallel_for(kJobs, 2, [&](int j) { x[static_cast<std::size_t>(j)] = solve(); });
  for (int j = 0; j < kJobs; ++j) EXPECT_TRUE(x[static_cast<std::size_t>(j)] == one) << "job " << j;
}

}  // namespace
}  // namespace shroudsim::linalg
