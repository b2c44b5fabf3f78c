#pragma once
// Independent tasks (the points of a study) over the threads of this process and, when the
// program runs under an MPI launcher (`mpirun -n K shroudsim study CASE`, or `srun`), over
// the threads of every rank of the job. docs/contract.md "Studies on several processes".
//
// Assignment is dynamic: a thread that finishes a task asks for the next one, since tasks
// differ in cost by orders of magnitude. Rank 0 owns the task list and receives every
// result; the other ranks serve: they run what rank 0 hands out until it releases them.
// Tasks and results are JSON values (a point's case overrides and folder; its status and
// peak), so the pool knows nothing of what a task is.
//
//   distributed::Session mpi(argc, argv);   // main(): MPI_Init only under a launcher
//   auto& w = distributed::world();
//   if (w.rank() == 0) {
//     run_tasks(tasks, {threads}, run, on_result);   // as often as the command needs
//     w.release(status);                             // once, whatever happened
//   } else {
//     return serve(threads, run);                    // rank 0's status
//   }
//
// Built without MPI, or started without a launcher, the world has one rank and run_tasks is
// a thread pool. A rank that dies takes the job down with it (the launcher's default: no
// hang); the points it had finished are in their folders and `study --resume` reruns the rest.
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace shroudsim::distributed {

using Json = nlohmann::json;
/// Runs one task and returns its result. Must not throw: a failed task is a result too.
using TaskRunner = std::function<Json(const Json& task)>;

/// This process's place in the job: rank and size (0 and 1 without a launcher).
class World {
 public:
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// More than one rank: the tasks of rank 0 are shared with the others.
  bool distributed() const { return size_ > 1; }
  /// Threads a rank runs when the user did not say (--threads 0): the hardware threads of the
  /// node shared among the ranks on it, at least one.
  int default_threads() const;
  /// Every rank says whether it is ready; true on every rank when all are (collective).
  bool all_ok(bool ok) const;
  /// Rank 0's text on every rank (collective).
  std::string broadcast(const std::string& text) const;
  /// Rank 0: the run is over, with this exit status; every serving rank's serve() returns it.
  /// Call once on rank 0, also when the run failed before any task. No-op with one rank.
  void release(int status);

 private:
  friend class Session;
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool mpi_initialized_ = false;  ///< this process called MPI_Init (Session finalizes it)
  bool released_ = false;
};

/// The job's world for this process's lifetime: initialises MPI when the process was started
/// by an MPI launcher (its environment says so) and the program was built with MPI, and
/// finalises it at the end. One per process, in main().
class Session {
 public:
  Session(int* argc, char*** argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

/// The world of this process (one rank when no Session is alive).
World& world();

struct PoolOptions {
  int threads = 1;  ///< workers on this rank (each runs one task at a time)
  /// The first task runs alone before any other starts: it fills the caches every task
  /// reads (the mesh and modes in <case dir>/.cache), so that no two workers compute them.
  bool first_alone = true;
};

/// Rank 0: runs every task once, on `options.threads` threads here and the threads of the
/// serving ranks. on_result(i, result) is called once per task, one call at a time, as
/// results arrive. Returns the number of workers (threads over all ranks) that served.
int run_tasks(const std::vector<Json>& tasks, const PoolOptions& options, const TaskRunner& run,
              const std::function<void(std::size_t, const Json&)>& on_result);

/// Ranks > 0: runs the tasks rank 0 hands out on `threads` threads, until rank 0 releases
/// the job; returns the exit status rank 0 released it with.
int serve(int threads, const TaskRunner& run);

}  // namespace shroudsim::distributed
