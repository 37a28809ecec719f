// The processing service's bounded pool: admission, order, cancellation.
#include "bsls/processing/work_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace bsls::processing {
namespace {

TEST(WorkPool, AdmitsWorkersPlusQueueAndRefusesTheRest) {
  WorkPool pool(2, 1);
  std::vector<WorkPool::Ticket> held;
  for (int i = 0; i < 3; ++i) {
    auto t = pool.TryAdmit();
    ASSERT_TRUE(t.has_value());
    held.push_back(std::move(*t));
  }
  EXPECT_FALSE(pool.TryAdmit().has_value());
  EXPECT_EQ(pool.Stats().rejected, 1u);
  EXPECT_EQ(pool.Stats().waiting, 3);
  held.pop_back();
  EXPECT_TRUE(pool.TryAdmit().has_value());
}

TEST(WorkPool, ServesWaitersInArrivalOrder) {
  WorkPool pool(1, 3);
  auto first = pool.TryAdmit();
  ASSERT_TRUE(first->WaitForWorker({}));
  std::vector<int> order;
  std::mutex mutex;
  std::vector<std::thread> threads;
  for (int i = 0; i < 3; ++i) {
    auto ticket = pool.TryAdmit();
    ASSERT_TRUE(ticket.has_value());
    threads.emplace_back([&, i, t = std::make_shared<WorkPool::Ticket>(std::move(*ticket))] {
      ASSERT_TRUE(t->WaitForWorker({}));
      std::lock_guard lock(mutex);
      order.push_back(i);
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(pool.Stats().busy, 1);
  first.reset();  // each thread then holds the worker until its ticket dies
  for (auto& t : threads) t.join();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(pool.Stats().completed, 4u);
  EXPECT_EQ(pool.Stats().busy, 0);
}

TEST(WorkPool, ACancelledWaiterLeavesTheQueue) {
  WorkPool pool(1, 1);
  auto worker = pool.TryAdmit();
  ASSERT_TRUE(worker->WaitForWorker({}));
  auto waiter = pool.TryAdmit();
  std::atomic<bool> cancel{false};
  std::thread t([&] { EXPECT_FALSE(waiter->WaitForWorker([&] { return cancel.load(); })); });
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(pool.Stats().waiting, 1);
  cancel = true;
  t.join();
  EXPECT_EQ(pool.Stats().waiting, 0);
  EXPECT_TRUE(pool.TryAdmit().has_value());
}

}  // namespace
}  // namespace bsls::processing
