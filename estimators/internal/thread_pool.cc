#include "estimators/internal/thread_pool.h"

#include <system_error>

#include "glog/logging.h"

namespace imusysid {
namespace internal {

ThreadPool::ThreadPool(int num_threads) {
  CHECK_GE(num_threads, 1);  // from a validated option (PopulationEvaluator)
  workers_.reserve(static_cast<std::size_t>(num_threads - 1));
  for (int w = 1; w < num_threads; ++w) {
    // A thread the system cannot start leaves the pool smaller (Run's tasks
    // share their work, so fewer workers give the same result); the
    // exception would leave the started ones unjoined.
    try {
      workers_.emplace_back([this, w] { WorkerLoop(w); });
    } catch (const std::system_error&) {
      break;
    }
  }
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (auto& worker : workers_) worker.join();
}

void ThreadPool::Run(const std::function<void(int)>& task) {
  if (workers_.empty()) {
    task(0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    CHECK(task_ == nullptr) << "ThreadPool::Run is not reentrant";
    task_ = &task;
    open_ = true;
    ++section_;
  }
  start_.notify_all();
  task(0);
  std::unique_lock<std::mutex> lock(mutex_);
  // The work is done or being finished by the workers that joined; the rest
  // must not start on a task that is about to go out of scope.
  open_ = false;
  done_.wait(lock, [this] { return active_ == 0; });
  task_ = nullptr;
}

void ThreadPool::WorkerLoop(int worker) {
  std::uint64_t seen = 0;
  for (;;) {
    const std::function<void(int)>* task = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [this, seen] { return stop_ || section_ != seen; });
      if (stop_) return;
      seen = section_;
      if (!open_) continue;
      task = task_;
      ++active_;
    }
    (*task)(worker);
    bool last = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      last = --active_ == 0;
    }
    if (last) done_.notify_one();
  }
}

}  // namespace internal
}  // namespace imusysid
