#include "bsls/service/stalled_writes.h"

#include <grpc/grpc.h>
#include <grpc/support/alloc.h>
#include <spdlog/spdlog.h>

#include <vector>

namespace bsls::service {

StalledWrites::StalledWrites(std::chrono::milliseconds limit)
    : limit_(limit), thread_([this] { Run(); }) {}

StalledWrites::~StalledWrites() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [id, entry] : watched_) grpc_call_unref(entry.call);
    watched_.clear();
  }
  wake_.notify_all();
  thread_.join();
}

StalledWrites::Watch::Watch(StalledWrites& owner, grpc_call* call, const char* what)
    : owner_(owner) {
  // The call is referenced while watched: the watch thread may cancel it
  // after the stream let go of it.
  grpc_call_ref(call);
  {
    std::lock_guard lock(owner_.mutex_);
    id_ = owner_.next_id_++;
    owner_.watched_[id_] = {std::chrono::steady_clock::now() + owner_.limit_, call, what};
  }
  owner_.wake_.notify_all();
}

StalledWrites::Watch::~Watch() {
  grpc_call* call = nullptr;
  {
    std::lock_guard lock(owner_.mutex_);
    if (auto it = owner_.watched_.find(id_); it != owner_.watched_.end()) {
      call = it->second.call;
      owner_.watched_.erase(it);
    }
  }
  if (call != nullptr) grpc_call_unref(call);
}

std::uint64_t StalledWrites::ended() const {
  std::lock_guard lock(mutex_);
  return ended_;
}

void StalledWrites::Run() {
  std::vector<Entry> expired;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    auto next = std::chrono::steady_clock::time_point::max();
    const auto now = std::chrono::steady_clock::now();
    for (auto it = watched_.begin(); it != watched_.end();) {
      if (it->second.until > now) {
        next = std::min(next, it->second.until);
        ++it;
        continue;
      }
      expired.push_back(std::move(it->second));
      it = watched_.erase(it);
      ++ended_;
    }
    if (!expired.empty()) {
      // Outside the lock: cancelling may run the stream's reactions, which
      // may watch or end a write of their own.
      lock.unlock();
      for (Entry& entry : expired) {
        // TryCancel would give the client CANCELLED; cancelling the call in
        // gRPC's core sends RESOURCE_EXHAUSTED with the reason and fails
        // the write in flight.
        const std::string reason = std::string("bslsd ended the ") + entry.what +
                                   " stream: the reader took no message for " +
                                   std::to_string(limit_.count()) +
                                   " ms (limits.stream_write_timeout_ms)";
        // The peer's name only now (before the cancel, which forgets it):
        // building it for every write watched would cost each stream
        // message a string.
        char* peer = grpc_call_get_peer(entry.call);
        grpc_call_cancel_with_status(entry.call, GRPC_STATUS_RESOURCE_EXHAUSTED, reason.c_str(),
                                     nullptr);
        spdlog::warn("{} (peer {})", reason, peer != nullptr ? peer : "unknown");
        gpr_free(peer);
        grpc_call_unref(entry.call);
      }
      expired.clear();
      lock.lock();
      continue;
    }
    if (next == std::chrono::steady_clock::time_point::max())
      wake_.wait(lock);
    else
      wake_.wait_until(lock, next);
  }
}

}  // namespace bsls::service
