// Server streams whose reader stopped reading: a stream message that a
// client never reads (and that set no deadline) stays in flight for ever,
// and with it the stream's slot (one of limits.max_preview_streams) and,
// with the sync API, a handler thread. StalledWrites watches each write in
// flight and ends the call of one that has not completed within the limit
// with RESOURCE_EXHAUSTED ("the reader took no message for N ms"): a sync
// Write returns false, a callback stream's write completes with ok false,
// and the stream's slot is free again.
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
#include <thread>

struct grpc_call;

namespace bsls::service {

class StalledWrites {
 public:
  // Ends calls whose Write takes longer than `limit`.
  explicit StalledWrites(std::chrono::milliseconds limit);
  // Stops the watch thread (calls still watched are left alone).
  ~StalledWrites();
  StalledWrites(const StalledWrites&) = delete;
  StalledWrites& operator=(const StalledWrites&) = delete;

  // Watches one write of a call while it exists: create it just before the
  // write (`call`: c_call() of a grpc::ServerContext or
  // grpc::CallbackServerContext) and destroy it when the write completes.
  // `what` names the stream in the status ("preview", "events").
  class Watch {
   public:
    Watch(StalledWrites& owner, grpc_call* call, const char* what);
    ~Watch();
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;

   private:
    StalledWrites& owner_;
    std::uint64_t id_;
  };

  // Calls ended so far because a Write stalled.
  std::uint64_t ended() const;

 private:
  struct Entry {
    std::chrono::steady_clock::time_point until;
    grpc_call* call;  // referenced while watched (grpc_call_ref)
    const char* what;
  };
  void Run();

  const std::chrono::milliseconds limit_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::uint64_t, Entry> watched_;  // writes in flight, by watch
  std::uint64_t next_id_ = 0;
  std::uint64_t ended_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_STALLED_WRITES_H_
