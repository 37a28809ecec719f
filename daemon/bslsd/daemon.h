// bslsd assembled: the store, the slide controller, the framestore on its
// capture thread, the event hub, the gRPC service, the gRPC server and the
// Unix-socket front door, started from a configuration and stopped in the
// order that loses nothing. main() wraps it with the privilege drop, systemd
// notification and signals; the request-handler fuzz target and the grab
// latency benchmark run the same assembly in-process.
#ifndef BSLS_BSLSD_DAEMON_H_
#define BSLS_BSLSD_DAEMON_H_

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>

#include "backends.h"
#include "bsls/rpc/tcp_acceptor.h"
#include "bsls/service/capture_device.h"
#include "bsls/service/capture_service.h"
#include "bsls/service/event_hub.h"
#include "bsls/service/processing_queue.h"
#include "bsls/service/unix_listener.h"
#include "config.h"

namespace bsls::bslsd {

// The Unix socket of `config.listen` bound, with its mode and group set and
// listening, but not yet accepting (nullptr when listen.unix_socket is
// empty). main() opens it before dropping privileges: setting the socket's
// group to one the daemon's user is not in needs CAP_CHOWN. Errors name the
// key (kInvalidArgument for an unknown group) or the socket and the reason.
Result<std::unique_ptr<service::UnixListener>> OpenUnixListener(const Config& config);

class Daemon {
 public:
  // Opens everything `config` names (after the privileged devices, already
  // opened, are handed in) and starts serving; `listener` is the socket
  // from OpenUnixListener (opened here when nullptr). `tick` is called from
  // the capture loop (the watchdog). Errors name the part that failed;
  // kInvalidArgument for what the configuration got wrong.
  static Result<std::unique_ptr<Daemon>> Start(
      const Config& config, PrivilegedDevices privileged, std::function<void()> tick = {},
      std::unique_ptr<service::UnixListener> listener = nullptr);
  // Drains (see Drain) if not done yet.
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  // Refuses new changes, stops accepting, ends streams and gives calls under
  // way `config.drain_timeout` to finish; then the server is down.
  void Drain();
  // Applies the store's retention policy (a no-op without one).
  void ApplyRetention();

  // The TCP port bound (0 without TCP).
  int tcp_port() const { return tcp_port_; }
  // The processing queue (disabled without processing.server).
  service::ProcessingQueue& processing() { return *processing_; }
  // Grabs acknowledged since start.
  std::uint64_t grabs_acknowledged() const { return service_->grabs_acknowledged(); }
  // The parts, for tests and the fuzz target.
  store::CaptureStore& store() { return *store_; }
  service::CaptureDevice& device() { return *device_; }

 private:
  Daemon() = default;

  Config config_;
  service::RolePolicy policy_;
  std::unique_ptr<store::CaptureStore> store_;
  service::EventHub events_;
  std::unique_ptr<slides::SlideController> slides_;
  std::unique_ptr<service::CaptureDevice> device_;
  std::unique_ptr<service::ProcessingQueue> processing_;
  service::PeerRegistry peers_;
  std::unique_ptr<service::CaptureService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<service::UnixListener> listener_;
  rpc::TcpListener tcp_;  // TCP connections, accepted here and handed to server_
  int tcp_port_ = 0;
  bool drained_ = false;
};

}  // namespace bsls::bslsd

#endif  // BSLS_BSLSD_DAEMON_H_
