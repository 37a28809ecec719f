#include "bsls/processing/work_pool.h"

#include <algorithm>
#include <cassert>
#include <utility>

namespace bsls::processing {

WorkPool::WorkPool(int workers, int queue) : workers_(workers), queue_(queue) {
  assert(workers >= 1 && queue >= 0);
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { Work(); });
}

WorkPool::~WorkPool() {
  std::map<std::uint64_t, Job> dropped;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    dropped.swap(ready_);
    for (const auto& [number, job] : dropped) Unqueue(number);
  }
  changed_.notify_all();
  for (auto& [number, job] : dropped)
    if (job.dropped) job.dropped();
  for (std::thread& t : threads_) t.join();
}

std::optional<WorkPool::Place> WorkPool::TryAdmit() {
  std::lock_guard lock(mutex_);
  if (stopping_ || busy_ + static_cast<int>(waiting_.size()) >= workers_ + queue_) {
    ++rejected_;
    return std::nullopt;
  }
  const std::uint64_t number = next_number_++;
  waiting_.push_back(number);
  return Place(this, number);
}

void WorkPool::Start(Place place, Job job) {
  assert(place.pool_ == this);
  place.pool_ = nullptr;  // the job holds the place from here
  bool drop = false;
  {
    std::lock_guard lock(mutex_);
    if (stopping_) {
      Unqueue(place.number_);
      drop = true;
    } else {
      ready_.emplace(place.number_, std::move(job));
    }
  }
  if (drop) {
    if (job.dropped) job.dropped();
    return;
  }
  changed_.notify_one();
}

bool WorkPool::Cancel(std::uint64_t number) {
  Job job;
  {
    std::lock_guard lock(mutex_);
    const auto it = ready_.find(number);
    if (it == ready_.end()) return false;
    job = std::move(it->second);
    ready_.erase(it);
    Unqueue(number);
  }
  changed_.notify_all();
  if (job.dropped) job.dropped();
  return true;
}

WorkPoolStats WorkPool::Stats() const {
  std::lock_guard lock(mutex_);
  return {workers_, queue_, busy_, static_cast<int>(waiting_.size()), completed_, rejected_};
}

void WorkPool::Unqueue(std::uint64_t number) {
  const auto it = std::find(waiting_.begin(), waiting_.end(), number);
  if (it != waiting_.end()) waiting_.erase(it);
}

void WorkPool::Leave(std::uint64_t number) {
  {
    std::lock_guard lock(mutex_);
    Unqueue(number);
  }
  changed_.notify_all();
}

// One worker: the started job of the earliest place, run without the lock,
// until the pool stops.
void WorkPool::Work() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stopping_ || !ready_.empty(); });
    if (ready_.empty()) return;  // stopping, nothing left
    auto first = ready_.begin();
    Job job = std::move(first->second);
    Unqueue(first->first);
    ready_.erase(first);
    ++busy_;
    lock.unlock();
    std::function<void()> then = job.run();
    job = {};  // what the job held goes before the worker counts as free
    lock.lock();
    --busy_;
    ++completed_;
    if (then) {
      lock.unlock();
      then();
      then = {};
      lock.lock();
    }
  }
}

WorkPool::Place::Place(Place&& other) noexcept : pool_(other.pool_), number_(other.number_) {
  other.pool_ = nullptr;
}

WorkPool::Place::~Place() {
  if (pool_ != nullptr) pool_->Leave(number_);
}

}  // namespace bsls::processing
