// bslsd's processing queue: every acknowledged grab is
// handed to the processing service named in the configuration, and what it
// returns is stored beside the capture as a sealed record
// (CaptureStore::PutProcessingResult).
//
// The queue is the capture store itself: a capture without a done or failed
// processing record is pending (CaptureStore::Unprocessed), so it survives
// restarts of the daemon and outages of the service without a second copy.
// One worker thread takes the oldest pending capture, sends it (both sides:
// ReconstructSession with both calibrations; one side: ProcessFrame with its
// calibration, or decode only without one), and
//   - stores the files and the record on success (event processing_finished),
//   - marks it failed for input the service refuses for good
//     (INVALID_ARGUMENT, FAILED_PRECONDITION, NOT_FOUND): not tried again,
//   - otherwise (unreachable, busy, deadline, damaged reply) counts the
//     attempt and tries again after a back-off that doubles up to
//     retry_max; gRPC's round_robin and the client's retries move the work
//     to another replica.
// The record (record.json) names the frames by SHA-256, the calibrations by
// id (and keeps a copy of each), the request, the service's result, every
// file's SHA-256 and both software versions: any figure can be recomputed.
//
// Thread-safety: Enqueue, Status and Stop are safe from any thread.
#ifndef BSLS_SERVICE_PROCESSING_QUEUE_H_
#define BSLS_SERVICE_PROCESSING_QUEUE_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "bsls/processing/processing_client.h"
#include "bsls/service/event_hub.h"
#include "bsls/store/capture_store.h"

namespace bsls::service {

struct ProcessingQueueOptions {
  processing::ClientOptions client;  // client.target empty: processing is off
  std::string left_calibration;      // calibration files' bytes ("" : none)
  std::string right_calibration;
  std::chrono::milliseconds retry_initial{1000};
  std::chrono::milliseconds retry_max{60000};
  std::string daemon_version;
};

class ProcessingQueue {
 public:
  // Borrowed parts must outlive the queue. Does not start work (Start).
  ProcessingQueue(store::CaptureStore* store, EventHub* events, ProcessingQueueOptions options);
  // Stops (see Stop).
  ~ProcessingQueue();
  ProcessingQueue(const ProcessingQueue&) = delete;
  ProcessingQueue& operator=(const ProcessingQueue&) = delete;

  // True when a processing service is configured.
  bool enabled() const { return !options_.client.target.empty(); }
  // Starts the worker (a no-op when not enabled); pending captures of
  // earlier runs are taken first, oldest first.
  void Start();
  // A capture was just acknowledged: process it soon.
  void Enqueue(const std::string& capture_id);
  // Cancels the call under way (its capture stays pending) and joins the worker.
  void Stop();
  // Captures processed (done or failed) since Start.
  std::uint64_t finished() const { return finished_; }

 private:
  enum class Outcome { kDone, kFailed, kRetry, kGone };
  // What the processing service made of one capture.
  struct Processed {
    std::map<std::string, std::string> files;  // name -> bytes
    store::ProcessingProvenance provenance;
  };
  void Run();
  // One capture: the call, then its results stored with their record.
  // `error` is set unless done.
  Outcome ProcessOne(const std::string& id, std::string* error);
  // A capture's frames of a side (left, right) by camera.
  using SideFrames = std::map<framestore::Camera, const framestore::GreyFrame*>;
  // Both sides with both calibrations: one ReconstructSession call.
  grpc::Status ReconstructBoth(const std::string& id, const SideFrames& frames, Processed* out);
  // Otherwise: one ProcessFrame call per side (a surface where its side has
  // a calibration).
  grpc::Status ProcessEachSide(const std::string& id, const SideFrames& frames, Processed* out);
  // Keeps the calibration of `camera`'s side (when configured) among the
  // files and names it in the provenance.
  void KeepCalibration(framestore::Camera camera, Processed* out) const;
  // The calibration (YAML) of `camera`'s side, empty when none is configured.
  const std::string& CalibrationOf(framestore::Camera camera) const {
    return camera == framestore::Camera::kLeft ? options_.left_calibration
                                               : options_.right_calibration;
  }
  // The outcome of a call that failed with `status`: a permanent failure
  // is recorded (not tried again), anything else tried later.
  Outcome Failed(const std::string& id, const grpc::Status& status, std::string* error);
  void Publish(const std::string& id);

  store::CaptureStore* store_;
  EventHub* events_;
  ProcessingQueueOptions options_;
  std::unique_ptr<processing::ProcessingClient> client_;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::string> queued_;  // arrived since the last scan
  bool rescan_ = true;              // read Unprocessed() again
  bool stopping_ = false;
  std::thread worker_;
  std::atomic<std::uint64_t> finished_{0};
};

// The API's view of a capture's processing record (`record` nullopt: never
// tried); `enabled` says whether a processing service is configured.
void FillProcessingStatus(const std::optional<store::ProcessingRecord>& record, bool enabled,
                          v1::ProcessingStatus* out);

}  // namespace bsls::service

#endif  // BSLS_SERVICE_PROCESSING_QUEUE_H_
