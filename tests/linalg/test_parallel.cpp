// linalg::parallel_for: every job, once; the BLAS on one thread whatever the worker count.
#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "linalg/blas.hpp"
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

}  // namespace
}  // namespace shroudsim::linalg
