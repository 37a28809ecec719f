// bsls-processd's gRPC service (proto/bsls/v1/processing.proto): frames in,
// labelled junctions, surfaces, measurements and calibrations out. Stateless
// apart from its CalibrationCache, so replicas are interchangeable.
//
// Every work call takes a place in the bounded WorkPool before it does
// anything costly (RESOURCE_EXHAUSTED at once when there is none), waits for
// one of the pool's workers, and runs there, checking between stages and
// inside the long ones whether the caller cancelled, the deadline passed or
// the service is draining; any of these stops the work. Requests are
// checked completely before the work starts: a bad field is
// INVALID_ARGUMENT naming it.
//
// ProcessFrame, ReconstructSession and Measure are on gRPC's callback API:
// their progress and files go out from the worker through a reactor, one
// write at a time, and a waiting call holds no thread. Calibrate's upload is
// read on its handler thread, which then waits for the work.
//
// Thread-safety: the handlers run concurrently on gRPC's threads, the work
// on the pool's; BeginDrain and Stats are safe from any thread.
#ifndef BSLS_PROCESSING_PROCESSING_SERVICE_H_
#define BSLS_PROCESSING_PROCESSING_SERVICE_H_

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "bsls/processing/calibration_cache.h"
#include "bsls/processing/work_pool.h"
#include "bsls/v1/processing.grpc.pb.h"

namespace bsls::processing {

struct ProcessingServiceOptions {
  int workers = 2;  // work that runs at once, >= 1
  int queue = 4;    // work that may wait for a worker, >= 0
  std::size_t calibration_cache_entries = 64;
  std::string replica;           // name in results and logs
  std::string software_version;  // recorded in results and calibration files
  // Where Calibrate unpacks an upload (a private folder per call, removed
  // after it); must exist.
  std::filesystem::path scratch_dir = std::filesystem::temp_directory_path();
  std::uint64_t max_upload_bytes = std::uint64_t{256} << 20;
  int max_upload_files = 256;
  std::size_t max_manifest_bytes = 1u << 20;
  int max_measurements = 100;  // figures in one MeasurementPlan
  // Pixels (width x height) of a frame that is worked on; a larger one is
  // refused with INVALID_ARGUMENT before any work (decoding is linear in
  // pixels: 8 Mpx is about 2 s of the worst frame on one core).
  std::int64_t max_frame_pixels = std::int64_t{8} << 20;
};

class ProcessingService final
    : public v1::Processing::WithCallbackMethod_ProcessFrame<
          v1::Processing::WithCallbackMethod_ReconstructSession<
              v1::Processing::WithCallbackMethod_Measure<v1::Processing::Service>>> {
 public:
  explicit ProcessingService(ProcessingServiceOptions options);

  // New work is refused (UNAVAILABLE) and work under way stops at its next
  // stage check; quick calls (calibrations, info) still answer.
  void BeginDrain();
  // The pool's load now.
  WorkPoolStats Stats() const { return pool_.Stats(); }
  // The calibration cache (for tests).
  CalibrationCache& calibrations() { return calibrations_; }

  grpc::ServerWriteReactor<v1::WorkEvent>* ProcessFrame(
      grpc::CallbackServerContext* context, const v1::ProcessFrameRequest* request) override;
  grpc::ServerWriteReactor<v1::WorkEvent>* ReconstructSession(
      grpc::CallbackServerContext* context, const v1::ReconstructSessionRequest* request) override;
  grpc::ServerWriteReactor<v1::WorkEvent>* Measure(grpc::CallbackServerContext* context,
                                                   const v1::MeasureRequest* request) override;
  // Calibrate's handler (the constructor puts it in the generated one's
  // place): the upload's messages arrive as bytes and are parsed here, so
  // that one that is not a CalibrateRequest is refused with INVALID_ARGUMENT
  // naming it (gRPC's typed reader shows it as the upload's end).
  grpc::Status CalibrateUpload(
      grpc::ServerContext* context,
      grpc::ServerReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>* stream);
  grpc::Status PutCalibration(grpc::ServerContext* context,
                              const v1::PutCalibrationRequest* request,
                              v1::CalibrationInfo* response) override;
  grpc::Status GetCalibration(grpc::ServerContext* context,
                              const v1::GetCalibrationRequest* request,
                              v1::CalibrationFile* response) override;
  grpc::Status GetServerInfo(grpc::ServerContext* context, const v1::GetServerInfoRequest* request,
                             v1::ServerInfo* response) override;

 private:
  using Emit = std::function<bool(const v1::WorkEvent&)>;
  struct Work;
  struct CallState;

  // The refusal of a call the pool cannot take now (draining or full), or
  // OK with its place in *place.
  grpc::Status Admit(std::optional<WorkPool::Place>* place);
  // The callback calls' common part: admission, `work` on a worker through
  // a WorkStream, the status.
  grpc::ServerWriteReactor<v1::WorkEvent>* StartWork(grpc::CallbackServerContext* context,
                                                     const std::string& call,
                                                     std::function<void(Work&)> work);
  // Runs `body` and maps what it throws to a status (OK when it returns).
  grpc::Status Guarded(const CallState& call, const std::function<void()>& body);
  // Calibrate's: admission, `prepare` on the handler thread (taking the
  // upload while the call holds its place), then `work` on a worker while
  // the handler thread waits.
  grpc::Status RunWaiting(grpc::ServerContext* context, const std::string& call, const Emit& emit,
                          const std::function<void(Work&)>& prepare,
                          const std::function<void(Work&)>& work);
  // `work` under Guarded, then the result event; the call's status.
  grpc::Status Perform(const CallState& call, Work& w, const std::function<void(Work&)>& work);

  // The calibration `source` names (cached on the way); throws the refusal
  // (NOT_FOUND, INVALID_ARGUMENT naming `field`) when there is none.
  std::shared_ptr<const CachedCalibration> ResolveCalibration(const v1::CalibrationSource& source,
                                                              const std::string& field);

  ProcessingServiceOptions options_;
  CalibrationCache calibrations_;
  std::atomic<bool> draining_{false};
  WorkPool pool_;  // last: its workers end before what their work uses goes
};

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_PROCESSING_SERVICE_H_
