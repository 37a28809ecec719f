#include "bsls/service/event_hub.h"

#include <google/protobuf/util/time_util.h>

namespace bsls::service {

EventHub::Watcher::~Watcher() {
  std::lock_guard lock(hub_->mutex_);
  hub_->watchers_.erase(this);
}

std::optional<v1::Event> EventHub::Watcher::Next(std::chrono::steady_clock::time_point deadline,
                                                 std::uint64_t* dropped) {
  std::unique_lock lock(hub_->mutex_);
  hub_->changed_.wait_until(lock, deadline, [&] { return hub_->closed_ || !queue_.empty(); });
  if (queue_.empty()) return std::nullopt;
  v1::Event event = std::move(queue_.front());
  queue_.pop_front();
  if (dropped) *dropped = dropped_;
  dropped_ = 0;
  return event;
}

std::unique_ptr<EventHub::Watcher> EventHub::Watch() {
  std::unique_ptr<Watcher> watcher(new Watcher(this));
  std::lock_guard lock(mutex_);
  watchers_.insert(watcher.get());
  return watcher;
}

void EventHub::Publish(v1::Event event) {
  *event.mutable_time() = google::protobuf::util::TimeUtil::GetCurrentTime();
  {
    std::lock_guard lock(mutex_);
    for (Watcher* watcher : watchers_) {
      if (watcher->queue_.size() >= queue_limit_) {
        watcher->queue_.pop_front();
        ++watcher->dropped_;
      }
      watcher->queue_.push_back(event);
    }
  }
  changed_.notify_all();
}

void EventHub::Close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

std::size_t EventHub::watchers() const {
  std::lock_guard lock(mutex_);
  return watchers_.size();
}

}  // namespace bsls::service
