// Where a processing command's work runs: on the processing service that
// --server names, or, when none is named, on the same service class in this
// process (bsls-processd's ProcessingService, reached over an in-process
// channel). Either way the command builds one request and reads one reply,
// so its files and its summary are the same (tests/cli/one_path_test.py).
#ifndef BSLS_CLIENTS_CLI_PROCESSING_ROUTE_H_
#define BSLS_CLIENTS_CLI_PROCESSING_ROUTE_H_

#include <grpcpp/grpcpp.h>

#include <map>
#include <memory>
#include <string>

#include "bsls/io/surface_file.h"
#include "bsls/processing/processing_client.h"
#include "bsls/processing/processing_service.h"
#include "daemon_connection.h"

namespace bsls::cli {

// Pixels of the largest frame a command takes: what one request message of
// the contracts carries (two 4096 x 4096 frames).
constexpr long kMaxLocalFramePixels = 4096L * 4096L;

class ProcessingRoute {
 public:
  // The route to `address`, or into this process when its target is empty.
  // CommandError (exit 2) for TCP to another machine without the TLS files,
  // (exit 3) when a TLS file cannot be read.
  explicit ProcessingRoute(const ServiceAddress& address);
  ~ProcessingRoute();
  ProcessingRoute(const ProcessingRoute&) = delete;
  ProcessingRoute& operator=(const ProcessingRoute&) = delete;

  // The client that does the work.
  processing::ProcessingClient& client() { return *client_; }
  // True when the work runs in this process.
  bool local() const { return server_ != nullptr; }
  // Prints the work's progress on stderr (ProgressPrinter): nothing when
  // `quiet`, nor for work in this process unless stderr is a terminal.
  processing::ProgressCallback Progress(bool quiet) const;
  // Throws the CommandError that the status of the work on `what` means
  // (CheckWork); returns when it is OK.
  void Check(const grpc::Status& status, const std::string& what) const;

 private:
  ServiceAddress address_;
  std::unique_ptr<processing::ProcessingService> service_;  // local only
  std::unique_ptr<grpc::Server> server_;                    // local only
  std::unique_ptr<processing::ProcessingClient> client_;
};

// Writes the PLY artifact `name` of `files` to `path` in the format its
// extension names: the bytes as they came for .ply (the request chose
// binary or ASCII), converted for .obj and .stl.
void WriteSurfaceArtifact(const std::string& path, const std::map<std::string, std::string>& files,
                          const std::string& name);

}  // namespace bsls::cli

#endif  // BSLS_CLIENTS_CLI_PROCESSING_ROUTE_H_
