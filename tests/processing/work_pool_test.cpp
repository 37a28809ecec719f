// The processing service's bounded pool: admission, order on its own
// workers, cancellation of a waiting job, and what happens to waiting jobs
// when the pool goes.
#include "bsls/processing/work_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace bsls::processing {
namespace {

using namespace std::chrono_literals;

// A job that waits for `gate` before it ends, so that the test decides when
// the worker comes free.
WorkPool::Job Blocking(std::shared_future<void> gate, std::promise<void>* started = nullptr) {
  return {[gate, started] {
            if (started) started->set_value();
            gate.wait();
            return std::function<void()>();
          },
          {}};
}

TEST(WorkPool, AdmitsWorkersPlusQueueAndRefusesTheRest) {
  WorkPool pool(2, 1);
  std::vector<WorkPool::Place> held;
  for (int i = 0; i < 3; ++i) {
    auto p = pool.TryAdmit();
    ASSERT_TRUE(p.has_value());
    held.push_back(std::move(*p));
  }
  EXPECT_FALSE(pool.TryAdmit().has_value());
  EXPECT_EQ(pool.Stats().rejected, 1u);
  EXPECT_EQ(pool.Stats().waiting, 3);
  held.pop_back();  // a place given up without a job is free again
  EXPECT_TRUE(pool.TryAdmit().has_value());
}

TEST(WorkPool, RunsStartedJobsInArrivalOrderOnItsOwnWorker) {
  WorkPool pool(1, 3);
  std::promise<void> open;
  std::promise<void> started;
  auto first = pool.TryAdmit();
  ASSERT_TRUE(first.has_value());
  pool.Start(std::move(*first), Blocking(open.get_future().share(), &started));
  started.get_future().wait();
  EXPECT_EQ(pool.Stats().busy, 1);
  std::vector<int> order;
  std::mutex mutex;
  std::vector<std::thread::id> threads;
  std::promise<void> all_done;
  for (int i = 0; i < 3; ++i) {
    auto place = pool.TryAdmit();
    ASSERT_TRUE(place.has_value());
    pool.Start(std::move(*place), {[&, i] {
                                     std::lock_guard lock(mutex);
                                     order.push_back(i);
                                     threads.push_back(std::this_thread::get_id());
                                     if (order.size() == 3) all_done.set_value();
                                     return std::function<void()>();
                                   },
                                   {}});
  }
  EXPECT_EQ(pool.Stats().waiting, 3);  // no thread of the test's waits for them
  open.set_value();
  all_done.get_future().wait();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
  for (std::thread::id id : threads) EXPECT_NE(id, std::this_thread::get_id());
  for (int i = 0; i < 100 && pool.Stats().completed < 4; ++i) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(pool.Stats().completed, 4u);
  EXPECT_EQ(pool.Stats().busy, 0);
}

TEST(WorkPool, WhatAJobLeavesForLaterRunsWithTheWorkerCountedFree) {
  WorkPool pool(1, 0);
  std::promise<int> busy_then;
  auto place = pool.TryAdmit();
  pool.Start(
      std::move(*place),
      {[&] { return std::function<void()>([&] { busy_then.set_value(pool.Stats().busy); }); }, {}});
  EXPECT_EQ(busy_then.get_future().get(), 0);
}

TEST(WorkPool, ACancelledJobLeavesTheQueueWithoutRunning) {
  WorkPool pool(1, 1);
  std::promise<void> open;
  std::promise<void> started;
  auto running = pool.TryAdmit();
  const std::uint64_t running_number = running->number();
  pool.Start(std::move(*running), Blocking(open.get_future().share(), &started));
  started.get_future().wait();
  auto waiter = pool.TryAdmit();
  ASSERT_TRUE(waiter.has_value());
  const std::uint64_t number = waiter->number();
  std::atomic<bool> ran{false}, dropped{false};
  pool.Start(std::move(*waiter), {[&] {
                                    ran = true;
                                    return std::function<void()>();
                                  },
                                  [&] { dropped = true; }});
  EXPECT_EQ(pool.Stats().waiting, 1);
  EXPECT_TRUE(pool.Cancel(number));
  EXPECT_TRUE(dropped);
  EXPECT_EQ(pool.Stats().waiting, 0);
  EXPECT_TRUE(pool.TryAdmit().has_value());
  EXPECT_FALSE(pool.Cancel(running_number));  // running: it stops by its own checks
  open.set_value();
  for (int i = 0; i < 100 && pool.Stats().busy != 0; ++i) std::this_thread::sleep_for(5ms);
  EXPECT_FALSE(ran);
}

TEST(WorkPool, JobsStillWaitingWhenThePoolGoesAreDropped) {
  std::promise<void> open;
  std::promise<void> started;
  std::atomic<int> dropped{0}, ran{0};
  std::thread release;
  {
    WorkPool pool(1, 2);
    auto first = pool.TryAdmit();
    pool.Start(std::move(*first), Blocking(open.get_future().share(), &started));
    started.get_future().wait();
    for (int i = 0; i < 2; ++i) {
      auto place = pool.TryAdmit();
      pool.Start(std::move(*place), {[&] {
                                       ++ran;
                                       return std::function<void()>();
                                     },
                                     [&] { ++dropped; }});
    }
    release = std::thread([&] {
      std::this_thread::sleep_for(20ms);
      open.set_value();
    });
  }  // waits for the running job, drops the two waiting ones
  release.join();
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(ran, 0);
}

}  // namespace
}  // namespace bsls::processing
