// The processing service's bounded pool: at most `workers` calls compute at
// once and at most `queue` more wait for a worker, first come first served.
// Beyond that a call is refused at once (the service answers
// RESOURCE_EXHAUSTED) instead of piling up threads and memory.
//
// The work itself runs on the caller's thread (the gRPC handler) once it
// holds a worker: progress is written from the thread that does the work,
// and a cancelled call leaves the queue without ever taking a worker.
//
// Thread-safety: every member is safe from any thread.
#ifndef BSLS_PROCESSING_WORK_POOL_H_
#define BSLS_PROCESSING_WORK_POOL_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>

namespace bsls::processing {

struct WorkPoolStats {
  int workers = 0;
  int queue = 0;
  int busy = 0;                 // holding a worker now
  int waiting = 0;              // admitted, waiting for a worker
  std::uint64_t completed = 0;  // tickets that held a worker and were released
  std::uint64_t rejected = 0;   // TryAdmit refusals
};

class WorkPool {
 public:
  // A place in the pool: queued first, then (WaitForWorker) a worker.
  // Leaving scope gives the place back.
  class Ticket {
   public:
    Ticket(Ticket&& other) noexcept;
    Ticket& operator=(Ticket&&) = delete;
    Ticket(const Ticket&) = delete;
    ~Ticket();

    // Waits for a worker in turn; false (the ticket then holds nothing) when
    // `cancelled` returns true first. `cancelled` is polled every `poll`.
    bool WaitForWorker(const std::function<bool()>& cancelled,
                       std::chrono::milliseconds poll = std::chrono::milliseconds(20));

   private:
    friend class WorkPool;
    Ticket(WorkPool* pool, std::uint64_t number) : pool_(pool), number_(number) {}
    WorkPool* pool_;
    std::uint64_t number_;
    bool working_ = false;
  };

  // workers >= 1, queue >= 0 (asserted: the configuration checks them).
  WorkPool(int workers, int queue);
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // A ticket when a worker or a queue place is free; nullopt (counted as
  // rejected) when all are taken.
  std::optional<Ticket> TryAdmit();
  // The pool's size and load now.
  WorkPoolStats Stats() const;

 private:
  void Leave(std::uint64_t number, bool working);

  const int workers_;
  const int queue_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::uint64_t> waiting_;  // ticket numbers in arrival order
  std::uint64_t next_number_ = 0;
  int busy_ = 0;
  std::uint64_t completed_ = 0;
  std::uint64_t rejected_ = 0;
};

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_WORK_POOL_H_
