#include "bsls/processing/work_pool.h"

#include <algorithm>
#include <cassert>

namespace bsls::processing {

WorkPool::WorkPool(int workers, int queue) : workers_(workers), queue_(queue) {
  assert(workers >= 1 && queue >= 0);
}

std::optional<WorkPool::Ticket> WorkPool::TryAdmit() {
  std::lock_guard lock(mutex_);
  if (busy_ + static_cast<int>(waiting_.size()) >= workers_ + queue_) {
    ++rejected_;
    return std::nullopt;
  }
  const std::uint64_t number = next_number_++;
  waiting_.push_back(number);
  return Ticket(this, number);
}

WorkPoolStats WorkPool::Stats() const {
  std::lock_guard lock(mutex_);
  return {workers_, queue_, busy_, static_cast<int>(waiting_.size()), completed_, rejected_};
}

void WorkPool::Leave(std::uint64_t number, bool working) {
  {
    std::lock_guard lock(mutex_);
    if (working) {
      --busy_;
      ++completed_;
    } else {
      const auto it = std::find(waiting_.begin(), waiting_.end(), number);
      if (it != waiting_.end()) waiting_.erase(it);
    }
  }
  changed_.notify_all();
}

WorkPool::Ticket::Ticket(Ticket&& other) noexcept
    : pool_(other.pool_), number_(other.number_), working_(other.working_) {
  other.pool_ = nullptr;
}

WorkPool::Ticket::~Ticket() {
  if (pool_ != nullptr) pool_->Leave(number_, working_);
}

bool WorkPool::Ticket::WaitForWorker(const std::function<bool()>& cancelled,
                                     std::chrono::milliseconds poll) {
  assert(pool_ != nullptr && !working_);
  std::unique_lock lock(pool_->mutex_);
  while (true) {
    if (pool_->busy_ < pool_->workers_ && pool_->waiting_.front() == number_) {
      pool_->waiting_.pop_front();
      ++pool_->busy_;
      working_ = true;
      lock.unlock();
      pool_->changed_.notify_all();  // the next in line may be served too
      return true;
    }
    lock.unlock();
    if (cancelled && cancelled()) {
      WorkPool* pool = pool_;
      pool_ = nullptr;
      pool->Leave(number_, false);
      return false;
    }
    lock.lock();
    pool_->changed_.wait_for(lock, poll);
  }
}

}  // namespace bsls::processing
