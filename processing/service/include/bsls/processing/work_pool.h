// The processing service's bounded pool: `workers` threads of its own
// compute the admitted calls' work, at most `queue` more calls wait for one,
// first come first served. Beyond that a call is refused at once (the
// service answers RESOURCE_EXHAUSTED) instead of piling up memory.
//
// A call takes a Place first (TryAdmit), may do something while it waits
// (Calibrate takes its upload), then hands its Job over (Start). A waiting
// call holds no thread: its job runs on a worker in turn, or is dropped when
// the call is cancelled before (Cancel) or the pool goes away.
//
// Thread-safety: every member is safe from any thread. A job's `run` and
// `dropped` are called without the pool's lock, exactly one of them once.
#ifndef BSLS_PROCESSING_WORK_POOL_H_
#define BSLS_PROCESSING_WORK_POOL_H_

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace bsls::processing {

struct WorkPoolStats {
  int workers = 0;
  int queue = 0;
  int busy = 0;                 // jobs running on a worker now
  int waiting = 0;              // admitted, waiting for a worker
  std::uint64_t completed = 0;  // jobs that ran to their end
  std::uint64_t rejected = 0;   // TryAdmit refusals
};

class WorkPool {
 public:
  // What an admitted call does: `run` on a worker in its turn, or `dropped`
  // instead when it is cancelled while it waits or the pool goes away.
  // What `run` returns (may be empty) is called on the worker once the pool
  // counts it free again: a call's status goes out there, so a caller that
  // has its answer finds the worker free.
  struct Job {
    std::function<std::function<void()>()> run;
    std::function<void()> dropped;
  };

  // A place in the queue; given back when it goes without being started.
  class Place {
   public:
    Place(Place&& other) noexcept;
    Place& operator=(Place&&) = delete;
    Place(const Place&) = delete;
    ~Place();

    // The place's number (Cancel's argument).
    std::uint64_t number() const { return number_; }

   private:
    friend class WorkPool;
    Place(WorkPool* pool, std::uint64_t number) : pool_(pool), number_(number) {}
    WorkPool* pool_;
    std::uint64_t number_;
  };

  // Starts `workers` threads; workers >= 1, queue >= 0 (asserted: the
  // configuration checks them).
  WorkPool(int workers, int queue);
  // Drops the jobs still waiting and joins the workers once their jobs end.
  ~WorkPool();
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // A place when a worker or a queue place is free; nullopt (counted as
  // rejected) when all are taken.
  std::optional<Place> TryAdmit();
  // Hands `job` over for `place`: it runs on the first free worker after
  // the jobs started from earlier places.
  void Start(Place place, Job job);
  // Drops the job of place `number` (its `dropped` is called here) or the
  // place itself if it still waits; false when its job runs or ran already.
  bool Cancel(std::uint64_t number);
  // The pool's size and load now.
  WorkPoolStats Stats() const;

 private:
  // Takes place `number` out of the waiting ones (the lock held).
  void Unqueue(std::uint64_t number);
  void Leave(std::uint64_t number);
  void Work();

  const int workers_;
  const int queue_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::uint64_t> waiting_;   // admitted places, in arrival order
  std::map<std::uint64_t, Job> ready_;  // started jobs that wait, by place
  std::uint64_t next_number_ = 0;
  int busy_ = 0;
  std::uint64_t completed_ = 0;
  std::uint64_t rejected_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_WORK_POOL_H_
