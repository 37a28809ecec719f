// Server streams whose reader stopped reading: with the sync API
// a stream message is written by a blocking Write, which a client that never
// reads (and set no deadline) holds for ever, and with it the stream's slot
// (one of limits.max_preview_streams) and a handler thread. StalledWrites
// watches each Write in flight and ends the call of one that has not
// completed within the limit with RESOURCE_EXHAUSTED ("the reader took no
// message for N ms"): the Write returns false, the handler returns and its
// slot is free again.
//
// Thread-safety: every member is safe from any thread. The watch thread
// starts in the constructor and is joined in the destructor.
#ifndef BSLS_SERVICE_STALLED_WRITES_H_
#define BSLS_SERVICE_STALLED_WRITES_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace grpc {
class ServerContext;
}

namespace bsls::service {

class StalledWrites {
 public:
  // Ends calls whose Write takes longer than `limit`.
  explicit StalledWrites(std::chrono::milliseconds limit);
  // Stops the watch thread (calls still watched are left alone).
  ~StalledWrites();
  StalledWrites(const StalledWrites&) = delete;
  StalledWrites& operator=(const StalledWrites&) = delete;

  // Watches one Write of `context`'s call while it exists: create it just
  // before the Write, on the handler's stack. `what` names the stream in
  // the status ("preview", "events").
  class Watch {
   public:
    Watch(StalledWrites& owner, grpc::ServerContext* context, const char* what);
    ~Watch();
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;

   private:
    StalledWrites& owner_;
    grpc::ServerContext* context_;
  };

  // Calls ended so far because a Write stalled.
  std::uint64_t ended() const;

 private:
  struct Entry {
    std::chrono::steady_clock::time_point until;
    const char* what;
  };
  void Run();

  const std::chrono::milliseconds limit_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<grpc::ServerContext*, Entry> watched_;  // Writes in flight
  std::uint64_t ended_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_STALLED_WRITES_H_
