#pragma once
// The worker pool for independent jobs run in parallel (harmonic indices
// in `modes` and `campbell`, points in `study`).
//
//   const int workers = linalg::worker_count(ctx.threads, jobs);
//   linalg::parallel_for(jobs, workers, [&](int i) { ...job i... });
//
// Each index runs once, on one of `workers` threads (the calling thread included), taken in
// increasing order. The BLAS runs on one thread meanwhile (linalg::SerialBlasScope), whatever
// the number of workers: OpenBLAS's own threads on top of the workers oversubscribe the
// cores, and a job's round-off must not depend on the worker count (a factorization with a
// threaded BLAS under one worker gave other modes, to round-off, than under two: --threads 1
// and 2 then traced different curves on the same sector; docs/continuation.md,
// "Determinism"). With two or more workers, each one's OpenMP regions (CHOLMOD's
// factorization) also run on its own thread (linalg::SerialOpenMPScope). A job should catch
// its own exceptions; one that escapes is rethrown after all workers have finished (the
// first one only).
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "linalg/blas.hpp"

namespace shroudsim::linalg {

/// `requested` workers (0: one per hardware thread), at least 1 and at most `jobs`.
inline int worker_count(int requested, int jobs) {
  const int want = requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, std::min(want, jobs));
}

template <typename Job>
void parallel_for(int jobs, int workers, Job&& job) {
  std::atomic<int> next{0};
  std::mutex lock;
  std::exception_ptr failure;
  auto work = [&] {
    // Each worker's OpenMP regions on its own thread (linalg::SerialOpenMPScope), for the
    // same reason as the serial BLAS: the workers already fill the cores.
    std::optional<linalg::SerialOpenMPScope> serial_openmp;
    if (workers > 1) serial_openmp.emplace();
    for (int i; (i = next++) < jobs;) {
      try {
        job(i);
      } catch (...) {
        std::lock_guard<std::mutex> g(lock);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  linalg::SerialBlasScope serial;
  if (workers <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (int t = 1; t < workers; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace shroudsim::linalg
