// bsls-processd's gRPC service (proto/bsls/v1/processing.proto): frames in,
// labelled junctions, surfaces, measurements and calibrations out. Stateless
// apart from its CalibrationCache, so replicas are interchangeable.
//
// Every work call takes a place in the bounded WorkPool before it does
// anything costly (RESOURCE_EXHAUSTED at once when there is none), waits for
// a worker, and runs on its own handler thread, checking between stages
// whether the caller cancelled, the deadline passed or the service is
// draining; any of these stops the work. Requests are checked completely
// before the work starts: a bad field is INVALID_ARGUMENT naming it.
//
// Thread-safety: the handlers run concurrently on gRPC's threads; BeginDrain
// and Stats are safe from any thread.
#ifndef BSLS_PROCESSING_PROCESSING_SERVICE_H_
#define BSLS_PROCESSING_PROCESSING_SERVICE_H_

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
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

class ProcessingService final : public v1::Processing::Service {
 public:
  explicit ProcessingService(ProcessingServiceOptions options);

  // New work is refused (UNAVAILABLE) and work under way stops at its next
  // stage check; quick calls (calibrations, info) still answer.
  void BeginDrain();
  // The pool's load now.
  WorkPoolStats Stats() const { return pool_.Stats(); }
  // The calibration cache (for tests).
  CalibrationCache& calibrations() { return calibrations_; }

  grpc::Status ProcessFrame(grpc::ServerContext* context, const v1::ProcessFrameRequest* request,
                            grpc::ServerWriter<v1::WorkEvent>* writer) override;
  grpc::Status ReconstructSession(grpc::ServerContext* context,
                                  const v1::ReconstructSessionRequest* request,
                                  grpc::ServerWriter<v1::WorkEvent>* writer) override;
  grpc::Status Measure(grpc::ServerContext* context, const v1::MeasureRequest* request,
                       grpc::ServerWriter<v1::WorkEvent>* writer) override;
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

  // Admission, `prepare` (may be empty: what a call does while queued, such
  // as taking an upload), the wait for a worker, the work and the mapping of
  // exceptions to statuses: shared by the three work calls.
  grpc::Status RunWork(grpc::ServerContext* context, const std::string& call, const Emit& emit,
                       const std::function<void(Work&)>& prepare,
                       const std::function<void(Work&)>& work);

  // The calibration `source` names (cached on the way); throws the refusal
  // (NOT_FOUND, INVALID_ARGUMENT naming `field`) when there is none.
  std::shared_ptr<const CachedCalibration> ResolveCalibration(const v1::CalibrationSource& source,
                                                              const std::string& field);

  ProcessingServiceOptions options_;
  WorkPool pool_;
  CalibrationCache calibrations_;
  std::atomic<bool> draining_{false};
};

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_PROCESSING_SERVICE_H_
