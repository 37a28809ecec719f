#include "bsls/service/event_hub.h"

#include <google/protobuf/util/time_util.h>

#include <vector>

namespace bsls::service {

EventHub::Watcher::~Watcher() {
  std::lock_guard lock(hub_->mutex_);
  hub_->watchers_.erase(this);
}

std::optional<v1::Event> EventHub::Watcher::Take(std::uint64_t* dropped) {
  std::lock_guard lock(hub_->mutex_);
  if (hub_->closed_ || queue_.empty()) return std::nullopt;
  v1::Event event = std::move(queue_.front());
  queue_.pop_front();
  if (dropped) *dropped = dropped_;
  dropped_ = 0;
  return event;
}

std::unique_ptr<EventHub::Watcher> EventHub::Watch(std::function<void()> on_event) {
  std::unique_ptr<Watcher> watcher(new Watcher(this));
  watcher->on_event_ = std::move(on_event);
  std::lock_guard lock(mutex_);
  watchers_.insert(watcher.get());
  return watcher;
}

void EventHub::Publish(v1::Event event) {
  *event.mutable_time() = google::protobuf::util::TimeUtil::GetCurrentTime();
  std::vector<std::function<void()>> notify;
  {
    std::lock_guard lock(mutex_);
    for (Watcher* watcher : watchers_) {
      if (watcher->queue_.size() >= queue_limit_) {
        watcher->queue_.pop_front();
        ++watcher->dropped_;
      }
      watcher->queue_.push_back(event);
      if (watcher->on_event_) notify.push_back(watcher->on_event_);
    }
  }
  // Copies, called without the lock: a watcher may go meanwhile; what its
  // callback holds outlives it.
  for (const auto& on_event : notify) on_event();
}

void EventHub::Close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
}

std::size_t EventHub::watchers() const {
  std::lock_guard lock(mutex_);
  return watchers_.size();
}

}  // namespace bsls::service
