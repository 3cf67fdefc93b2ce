// A fixed set of worker threads started once and reused for every parallel
// section of a run, so a population method pays for thread creation once
// instead of once per generation.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_THREAD_POOL_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_THREAD_POOL_H_

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace imusysid {
namespace internal {

// Run(task) is a work-sharing section: task(0) runs on the calling thread,
// and task(w) on each worker w that wakes up before the calling thread's
// task(0) has returned; Run returns when every task that started has
// returned. A worker that wakes later skips the section, so a worker that the
// OS does not schedule (a machine busy with other work) never makes the
// caller wait. Tasks must therefore share their work dynamically (e.g. take
// chunks from an atomic counter until none is left): the caller alone may
// end up doing all of it. Workers sleep on a condition variable between
// sections (no spinning). One Run at a time; the destructor joins the
// workers.
class ThreadPool {
 public:
  // num_threads ≥ 1; num_threads − 1 workers are started here, fewer where
  // the system cannot start a thread (num_threads() says how many).
  explicit ThreadPool(int num_threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  void Run(const std::function<void(int worker)>& task);

 private:
  void WorkerLoop(int worker);

  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  // All guarded by mutex_.
  const std::function<void(int)>* task_ = nullptr;
  std::uint64_t section_ = 0;  // incremented by each Run
  bool open_ = false;          // workers may still join the current section
  int active_ = 0;             // workers inside the current task
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_THREAD_POOL_H_
