#include "bsls/service/stalled_writes.h"

#include <grpc/grpc.h>
#include <grpcpp/server_context.h>
#include <spdlog/spdlog.h>

namespace bsls::service {

StalledWrites::StalledWrites(std::chrono::milliseconds limit)
    : limit_(limit), thread_([this] { Run(); }) {}

StalledWrites::~StalledWrites() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

StalledWrites::Watch::Watch(StalledWrites& owner, grpc::ServerContext* context, const char* what)
    : owner_(owner), context_(context) {
  {
    std::lock_guard lock(owner_.mutex_);
    owner_.watched_[context_] = {std::chrono::steady_clock::now() + owner_.limit_, what};
  }
  owner_.wake_.notify_all();
}

StalledWrites::Watch::~Watch() {
  // Under the mutex: once this returns, the watch thread no longer touches
  // the context (the handler may end and gRPC free it).
  std::lock_guard lock(owner_.mutex_);
  owner_.watched_.erase(context_);
}

std::uint64_t StalledWrites::ended() const {
  std::lock_guard lock(mutex_);
  return ended_;
}

void StalledWrites::Run() {
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
      // The sync API cannot abandon a blocked Write with a status of our
      // choosing (TryCancel gives the client CANCELLED); cancelling the
      // call in gRPC's core sends RESOURCE_EXHAUSTED with the reason and
      // makes the Write return false.
      const std::string reason = std::string("bslsd ended the ") + it->second.what +
                                 " stream: the reader took no message for " +
                                 std::to_string(limit_.count()) +
                                 " ms (limits.stream_write_timeout_ms)";
      grpc_call_cancel_with_status(it->first->c_call(), GRPC_STATUS_RESOURCE_EXHAUSTED,
                                   reason.c_str(), nullptr);
      spdlog::warn("{} (peer {})", reason, it->first->peer());
      ++ended_;
      it = watched_.erase(it);
    }
    if (next == std::chrono::steady_clock::time_point::max())
      wake_.wait(lock);
    else
      wake_.wait_until(lock, next);
  }
}

}  // namespace bsls::service
