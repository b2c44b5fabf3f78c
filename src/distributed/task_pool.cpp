// The work pool over threads and MPI ranks: see task_pool.hpp.
//
// Protocol (rank 0 = root; messages are JSON text):
//   root -> rank  kTagBatch  {"batch": b} a new set of tasks, or {"stop": true, "status": s}
//   slot -> root  kTagAsk    {"slot": t, "batch": b} plus, after a task, {"index": i, "result": r}
//   root -> slot  kTagReply + t  {"index": i, "task": ...} or {"none": true} (batch over for it)
//   rank -> root  kTagDone   {"batch": b} after its slots were all told "none"
// A slot is one worker thread of a serving rank; its MPI calls are serialised by a mutex of
// its rank (MPI_THREAD_SERIALIZED). Root's own workers take tasks from the same queue in
// memory; only root's main thread calls MPI (it polls, so a request never waits for a task).
#include "distributed/task_pool.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <iostream>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <utility>

#include "linalg/blas.hpp"

#ifdef SHROUDSIM_HAVE_MPI
#include <mpi.h>
#endif

namespace shroudsim::distributed {
namespace {

World g_world;

constexpr int kTagBatch = 1, kTagAsk = 2, kTagDone = 3, kTagReply = 100;

/// The queue of one batch on root: hands out indices in order; with first_alone, index 0
/// first and nothing else until its result is in.
class Queue {
 public:
  Queue(std::size_t n, bool first_alone) : n_(n), open_(!first_alone || n <= 1) {}
  /// A root worker's next task (waits while the first task runs alone); nullopt: none left.
  std::optional<std::size_t> take() {
    std::unique_lock<std::mutex> lock(m_);
    if (next_ == 0 && n_ > 0) return next_++;
    cv_.wait(lock, [&] { return open_; });
    if (next_ < n_) return next_++;
    return std::nullopt;
  }
  /// For a remote slot: nullopt with *wait set while the first task still runs alone.
  std::optional<std::size_t> try_take(bool* wait) {
    std::lock_guard<std::mutex> lock(m_);
    *wait = !open_;
    if (!open_ || next_ >= n_) return std::nullopt;
    return next_++;
  }
  void finished(std::size_t i) {
    {
      std::lock_guard<std::mutex> lock(m_);
      ++done_;
      if (i == 0) open_ = true;
    }
    cv_.notify_all();
  }
  bool all_done() {
    std::lock_guard<std::mutex> lock(m_);
    return done_ == n_;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::size_t n_, next_ = 0, done_ = 0;
  bool open_;
};

/// Root's workers on this process: take, run, report, until the queue is empty.
void run_local(Queue& queue, const std::vector<Json>& tasks, const TaskRunner& run,
               const std::function<void(std::size_t, const Json&)>& deliver) {
  for (std::optional<std::size_t> i; (i = queue.take());) {
    const Json result = run(tasks[*i]);
    deliver(*i, result);
    queue.finished(*i);
  }
}

#ifdef SHROUDSIM_HAVE_MPI
void send(const Json& message, int dest, int tag) {
  const std::string text = message.dump();
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

/// The next message matching (source, tag), possibly ANY; *status says who and which tag.
Json receive(int source, int tag, MPI_Status* status = nullptr) {
  MPI_Status st;
  MPI_Probe(source, tag, MPI_COMM_WORLD, &st);
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  std::string text(static_cast<std::size_t>(count), '\0');
  MPI_Recv(text.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (status) *status = st;
  return Json::parse(text);
}

/// Root's main thread during a batch: answers the serving slots until every task has its
/// result and every serving rank has finished the batch. Returns the number of remote slots
/// that asked for work.
int coordinate(Queue& queue, int batch, const std::vector<Json>& tasks,
               const std::function<void(std::size_t, const Json&)>& deliver) {
  std::deque<std::pair<int, int>> waiting;  // (rank, slot) asked while the first task ran alone
  std::set<std::pair<int, int>> slots;
  int ranks_done = 0;
  auto answer = [&](int rank, int slot) -> bool {
    bool wait = false;
    const std::optional<std::size_t> i = queue.try_take(&wait);
    if (wait) return false;
    send(i ? Json{{"index", *i}, {"task", tasks[*i]}} : Json{{"none", true}}, rank, kTagReply + slot);
    return true;
  };
  while (!(queue.all_done() && ranks_done == g_world.size() - 1)) {
    while (!waiting.empty() && answer(waiting.front().first, waiting.front().second)) waiting.pop_front();
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      continue;
    }
    const Json m = receive(st.MPI_SOURCE, st.MPI_TAG);
    if (m.value("batch", -1) != batch) {
      std::cerr << "shroudsim: error: rank " << st.MPI_SOURCE << " is out of step (batch " << m.value("batch", -1)
                << ", expected " << batch << ")\n";
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    if (st.MPI_TAG == kTagDone) {
      ++ranks_done;
      continue;
    }
    const int slot = m.at("slot").get<int>();
    slots.emplace(st.MPI_SOURCE, slot);
    if (m.contains("result")) {
      const std::size_t i = m.at("index").get<std::size_t>();
      deliver(i, m.at("result"));
      queue.finished(i);
    }
    if (!answer(st.MPI_SOURCE, slot)) waiting.emplace_back(st.MPI_SOURCE, slot);
  }
  return static_cast<int>(slots.size());
}

/// A serving rank's slot: asks, runs, reports with the next ask, until told "none".
void serve_slot(int slot, int batch, std::mutex& mpi, const TaskRunner& run) {
  Json ask = {{"slot", slot}, {"batch", batch}};
  for (;;) {
    Json reply;
    {
      std::lock_guard<std::mutex> lock(mpi);
      send(ask, 0, kTagAsk);
      reply = receive(0, kTagReply + slot);
    }
    if (reply.contains("none")) return;
    ask = {{"slot", slot}, {"batch", batch}, {"index", reply.at("index")}, {"result", run(reply.at("task"))}};
  }
}
#endif

}  // namespace

World& world() { return g_world; }

int World::default_threads() const {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, local_size_));
}

bool World::all_ok(bool ok) const {
#ifdef SHROUDSIM_HAVE_MPI
  if (size_ > 1) {
    int mine = ok ? 1 : 0, all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all == 1;
  }
#endif
  return ok;
}

std::string World::broadcast(const std::string& text) const {
#ifdef SHROUDSIM_HAVE_MPI
  if (size_ > 1) {
    int n = static_cast<int>(text.size());
    MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::string out = rank_ == 0 ? text : std::string(static_cast<std::size_t>(n), '\0');
    MPI_Bcast(out.data(), n, MPI_CHAR, 0, MPI_COMM_WORLD);
    return out;
  }
#endif
  return text;
}

void World::release(int status) {
  if (released_ || size_ <= 1 || rank_ != 0) return;
  released_ = true;
#ifdef SHROUDSIM_HAVE_MPI
  for (int r = 1; r < size_; ++r) send({{"stop", true}, {"status", status}}, r, kTagBatch);
#else
  (void)status;
#endif
}

Session::Session(int* argc, char*** argv) {
#ifdef SHROUDSIM_HAVE_MPI
  // Only under a launcher: a plain `shroudsim` run must not start MPI's runtime.
  const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK") ||
                        std::getenv("MPI_LOCALNRANKS");
  if (!launched) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  if (provided < MPI_THREAD_SERIALIZED) {
    std::cerr << "shroudsim: error: this MPI library does not allow calls from worker threads "
                 "(MPI_THREAD_SERIALIZED); the study cannot be distributed\n";
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &g_world.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &g_world.size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &g_world.local_size_);
  MPI_Comm_free(&node);
  g_world.mpi_initialized_ = true;
#else
  (void)argc, (void)argv;
#endif
}

Session::~Session() {
#ifdef SHROUDSIM_HAVE_MPI
  if (g_world.mpi_initialized_) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
#endif
  g_world = World{};
}

int run_tasks(const std::vector<Json>& tasks, const PoolOptions& options, const TaskRunner& run,
              const std::function<void(std::size_t, const Json&)>& on_result) {
  Queue queue(tasks.size(), options.first_alone);
  std::mutex deliver_lock;
  auto deliver = [&](std::size_t i, const Json& r) {
    std::lock_guard<std::mutex> lock(deliver_lock);
    on_result(i, r);
  };
  const int local = std::max(1, options.threads);
  // BLAS on one thread per worker: OpenBLAS's own threads on top of the workers would
  // oversubscribe the cores (linalg/blas.hpp).
  linalg::SerialBlasScope serial;
  std::vector<std::thread> pool;
  std::exception_ptr failure;
  for (int t = 0; t < local; ++t)
    pool.emplace_back([&] {
      try {
        run_local(queue, tasks, run, deliver);
      } catch (...) {
        std::lock_guard<std::mutex> lock(deliver_lock);
        if (!failure) failure = std::current_exception();
      }
    });
  int remote = 0;
#ifdef SHROUDSIM_HAVE_MPI
  if (g_world.distributed()) {
    static int batch = 0;
    ++batch;
    for (int r = 1; r < g_world.size(); ++r) send({{"batch", batch}}, r, kTagBatch);
    try {
      remote = coordinate(queue, batch, tasks, deliver);
    } catch (const std::exception& e) {
      // The serving ranks wait on this rank: a coordinator that cannot go on ends the job.
      std::cerr << "shroudsim: error: coordinating the study's ranks: " << e.what() << "\n";
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
  }
#endif
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return local + remote;
}

int serve(int threads, const TaskRunner& run) {
#ifdef SHROUDSIM_HAVE_MPI
  std::mutex mpi;
  for (;;) {
    const Json m = receive(0, kTagBatch);
    if (m.contains("stop")) return m.at("status").get<int>();
    const int batch = m.at("batch").get<int>();
    linalg::SerialBlasScope serial;
    std::vector<std::thread> pool;
    for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back([&, t] { serve_slot(t, batch, mpi, run); });
    for (auto& t : pool) t.join();
    send({{"batch", batch}}, 0, kTagDone);
  }
#else
  (void)threads, (void)run;
  return 0;
#endif
}

}  // namespace shroudsim::distributed
