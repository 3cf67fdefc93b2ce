// Tests of internal::ThreadPool: the calling thread always runs the task as
// worker 0, a worker that is awake joins the section, no thread runs a
// section twice, and the same workers serve every section.

#include "estimators/internal/thread_pool.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace imusysid {
namespace internal {
namespace {

TEST(ThreadPool, CallerIsWorkerZeroAndNoThreadRunsASectionTwice) {
  for (int threads : {1, 2, 5}) {
    SCOPED_TRACE(threads);
    ThreadPool pool(threads);
    EXPECT_EQ(pool.num_threads(), threads);
    for (int section = 0; section < 50; ++section) {
      std::vector<std::atomic<int>> calls(static_cast<std::size_t>(threads));
      std::thread::id worker0;
      pool.Run([&](int worker) {
        calls[static_cast<std::size_t>(worker)].fetch_add(1);
        if (worker == 0) worker0 = std::this_thread::get_id();
      });
      EXPECT_EQ(calls[0].load(), 1);
      for (int w = 1; w < threads; ++w) {
        EXPECT_LE(calls[static_cast<std::size_t>(w)].load(), 1)
            << "worker " << w;
      }
      EXPECT_EQ(worker0, std::this_thread::get_id());
    }
  }
}

// Worker 0 holds the section open until worker 1 has joined (or 30 s pass,
// which only a broken pool or a frozen machine reaches): the worker really
// runs tasks, on its own thread, and keeps doing so section after section.
TEST(ThreadPool, AwakeWorkersJoinAndAreReusedForEverySection) {
  ThreadPool pool(2);
  std::set<std::thread::id> seen;
  std::mutex seen_mutex;
  for (int section = 0; section < 20; ++section) {
    std::atomic<bool> joined{false};
    pool.Run([&](int worker) {
      {
        std::lock_guard<std::mutex> lock(seen_mutex);
        seen.insert(std::this_thread::get_id());
      }
      if (worker == 1) {
        joined = true;
        return;
      }
      const auto deadline =
          std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (!joined && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::yield();
      }
    });
    ASSERT_TRUE(joined) << "section " << section;
  }
  EXPECT_EQ(seen.size(), 2u) << "the caller and one worker, every time";
}

// The work-sharing pattern the population evaluator uses: chunks from an
// atomic counter. Every chunk is done exactly once, whoever joins.
TEST(ThreadPool, DynamicChunksAreEachDoneOnce) {
  ThreadPool pool(3);
  for (int section = 0; section < 100; ++section) {
    constexpr int kChunks = 37;
    std::vector<std::atomic<int>> done(kChunks);
    std::atomic<int> next{0};
    pool.Run([&](int /*worker*/) {
      for (int c = next.fetch_add(1); c < kChunks; c = next.fetch_add(1)) {
        done[static_cast<std::size_t>(c)].fetch_add(1);
      }
    });
    for (int c = 0; c < kChunks; ++c) {
      ASSERT_EQ(done[static_cast<std::size_t>(c)].load(), 1)
          << "section " << section << " chunk " << c;
    }
  }
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
