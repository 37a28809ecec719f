// The daemon's event stream (WatchEvents): slide changes, device lost/found,
// captures stored/deleted, camera/gain changes, errors. Each watcher has its
// own bounded queue; a watcher that does not keep up loses its oldest events
// (and is told how many), never holding up the publisher or other watchers.
//
// Thread-safety: every member is safe from any thread.
#ifndef BSLS_SERVICE_EVENT_HUB_H_
#define BSLS_SERVICE_EVENT_HUB_H_

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>

#include "bsls/v1/capture.pb.h"

namespace bsls::service {

class EventHub {
 public:
  // `queue_limit`: events kept per watcher before the oldest are dropped.
  explicit EventHub(std::size_t queue_limit = 256) : queue_limit_(queue_limit) {}

  // One watcher's queue.
  class Watcher {
   public:
    ~Watcher();
    // The next queued event, or nullopt when none is queued or the hub
    // closed; never waits. `dropped` counts events lost to overflow before it.
    std::optional<v1::Event> Take(std::uint64_t* dropped);

   private:
    friend class EventHub;
    explicit Watcher(EventHub* hub) : hub_(hub) {}
    EventHub* hub_;
    std::deque<v1::Event> queue_;
    std::uint64_t dropped_ = 0;
    std::function<void()> on_event_;
  };

  // Registers a watcher; it sees events published from now on, and
  // `on_event` is called after each is queued (on the publisher's thread,
  // without the hub's lock: it may Take, it must not block).
  std::unique_ptr<Watcher> Watch(std::function<void()> on_event);
  // Stamps `event` with the current time and queues it for every watcher.
  void Publish(v1::Event event);
  // Ends the hub: watchers take nothing more (shutdown).
  void Close();
  // Watchers registered now.
  std::size_t watchers() const;

 private:
  const std::size_t queue_limit_;
  mutable std::mutex mutex_;
  std::set<Watcher*> watchers_;
  bool closed_ = false;
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_EVENT_HUB_H_
